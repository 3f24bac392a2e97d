#include "web/html.h"

#include <fmt/format.h>

#include <cctype>
#include <cmath>
#include <ctime>
#include <stdexcept>

#include "driftlab/report/html_report.h"

namespace driftlab::server::web {

std::string Escape(std::string_view text) { return app::EscapeHtml(text); }

std::string UrlEncode(std::string_view text) {
  static constexpr char kHex[] = "0123456789ABCDEF";
  std::string out;
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if (std::isalnum(u) || c == '-' || c == '_' || c == '.' || c == '~') {
      out.push_back(c);
    } else {
      out.push_back('%');
      out.push_back(kHex[u >> 4]);
      out.push_back(kHex[u & 15]);
    }
  }
  return out;
}

std::string Page(const std::string& title, const std::string& section, const Viewer& viewer,
                 const std::string& body, const std::string& head_extra) {
  std::string html =
      "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
      "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
      "<title>" +
      Escape(title) +
      " · driftlab</title>\n"
      "<link rel=\"stylesheet\" href=\"/static/app.css\">\n"
      "<script src=\"/static/app.js\" defer></script>\n" +
      head_extra + "</head>\n<body>\n<header class=\"bar\"><span class=\"brand\">driftlab</span>\n";
  if (viewer.signed_in) {
    const auto entry = [&](const char* key, const char* href, const char* label) {
      return fmt::format("<a href=\"{}\"{}>{}</a>", href,
                         section == key ? " class=\"current\" aria-current=\"page\"" : "", label);
    };
    html += "<nav>" + entry("jobs", "/jobs", "Jobs") +
            entry("calibrations", "/calibrations", "Calibrations") +
            entry("catalog", "/catalog", "IMU catalogue") + "</nav>\n";
    html += "<form class=\"signout\" method=\"post\" action=\"/signout\"><span>" +
            Escape(viewer.owner) + "</span><input type=\"hidden\" name=\"csrf\" value=\"" +
            Escape(viewer.csrf) + "\"><button type=\"submit\">Sign out</button></form>\n";
  }
  html += "</header>\n<main>\n" + body + "</main>\n</body>\n</html>\n";
  return html;
}

std::string FormatUtc(std::optional<double> unix_s) {
  if (!unix_s || !std::isfinite(*unix_s) || *unix_s <= 0) return "–";
  const std::time_t t = static_cast<std::time_t>(*unix_s);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char text[32];
  std::strftime(text, sizeof(text), "%Y-%m-%d %H:%M:%S UTC", &tm);
  return text;
}

std::string FormatDuration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "–";
  const auto s = static_cast<uint64_t>(seconds);
  if (s < 60) return fmt::format("{} s", s);
  if (s < 3600) return fmt::format("{} min {:02} s", s / 60, s % 60);
  if (s < 86400) return fmt::format("{} h {:02} min", s / 3600, (s % 3600) / 60);
  return fmt::format("{} d {:02} h", s / 86400, (s % 86400) / 3600);
}

std::string FormatCount(uint64_t value) {
  std::string digits = std::to_string(value);
  std::string out;
  for (size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) out += "\u2009";
    out.push_back(digits[i]);
  }
  return out;
}

namespace {

// A recursive-descent reader of the JSON protobuf prints, writing the tree as it goes.
class JsonTreeWriter {
 public:
  JsonTreeWriter(std::string_view text, int open_depth) : text_(text), open_depth_(open_depth) {}

  std::string Write() {
    std::string out = "<div class=\"json\">";
    Value("", 0, &out);
    Space();
    if (at_ != text_.size()) throw std::runtime_error("trailing text");
    return out + "</div>";
  }

 private:
  static constexpr int kMaxDepth = 64;

  void Space() {
    while (at_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[at_]))) ++at_;
  }
  char Peek() {
    Space();
    if (at_ >= text_.size()) throw std::runtime_error("unexpected end");
    return text_[at_];
  }
  void Expect(char c) {
    if (Peek() != c) throw std::runtime_error("unexpected character");
    ++at_;
  }

  // A JSON string token, returned decoded only as far as display needs (escapes kept as written).
  std::string String() {
    Expect('"');
    const size_t begin = at_;
    while (at_ < text_.size() && text_[at_] != '"') at_ += text_[at_] == '\\' ? 2 : 1;
    if (at_ >= text_.size()) throw std::runtime_error("unterminated string");
    return std::string(text_.substr(begin, at_++ - begin));
  }

  std::string Scalar() {
    const size_t begin = at_;
    while (at_ < text_.size() && text_[at_] != ',' && text_[at_] != '}' && text_[at_] != ']' &&
           !std::isspace(static_cast<unsigned char>(text_[at_]))) {
      ++at_;
    }
    if (at_ == begin) throw std::runtime_error("empty value");
    return std::string(text_.substr(begin, at_ - begin));
  }

  static std::string Key(const std::string& key) {
    return key.empty() ? "" : "<span class=\"k\">" + Escape(key) + "</span>: ";
  }

  void Value(const std::string& key, int depth, std::string* out) {
    if (depth > kMaxDepth) throw std::runtime_error("too deep");
    const char c = Peek();
    if (c == '{' || c == '[') {
      const bool object = c == '{';
      ++at_;
      std::string items;
      int count = 0;
      if (Peek() != (object ? '}' : ']')) {
        for (;;) {
          std::string item_key;
          if (object) {
            item_key = String();
            Expect(':');
          } else {
            item_key = "[" + std::to_string(count) + "]";
          }
          items += "<li>";
          Value(item_key, depth + 1, &items);
          items += "</li>";
          ++count;
          if (Peek() == ',') {
            ++at_;
            continue;
          }
          break;
        }
      }
      Expect(object ? '}' : ']');
      const std::string summary =
          object ? fmt::format("{{…}} {} field{}", count, count == 1 ? "" : "s")
                 : fmt::format("[…] {} item{}", count, count == 1 ? "" : "s");
      *out += fmt::format(
          "<details{}><summary>{}<span class=\"n\">{}</span></summary><ul>{}</ul>"
          "</details>",
          depth < open_depth_ ? " open" : "", Key(key), summary, items);
      return;
    }
    const bool string = c == '"';
    const std::string value = string ? "\"" + String() + "\"" : Scalar();
    *out += "<span class=\"leaf\">" + Key(key) + "<span class=\"" + (string ? "s" : "v") + "\">" +
            Escape(value) + "</span></span>";
  }

  std::string_view text_;
  int open_depth_;
  size_t at_ = 0;
};

}  // namespace

std::string JsonTree(std::string_view json, int open_depth) {
  try {
    return JsonTreeWriter(json, open_depth).Write();
  } catch (const std::exception&) {
    return "<pre>" + Escape(json) + "</pre>";
  }
}

std::string Command(const std::string& text) {
  return "<pre class=\"cmd\"><code>" + Escape(text) + "</code></pre>\n";
}

}  // namespace driftlab::server::web
