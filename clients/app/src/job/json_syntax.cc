// CheckJsonSyntax (json_syntax.h): a state machine over RFC 8259's grammar (sections 2-7) with an
// explicit stack of open containers, so its cost is linear and its memory bounded by max_depth.
#include "driftlab/app/json_syntax.h"

#include <fmt/format.h>

#include <cstdint>
#include <string>
#include <vector>

#include "driftlab/spec_error.h"

namespace driftlab::app {
namespace {

class JsonSyntax {
 public:
  JsonSyntax(std::string_view text, std::string_view source, std::string_view kind, int max_depth)
      : text_(text), source_(source), kind_(kind), max_depth_(max_depth) {}

  void Check() {
    SkipSpace();
    Value();
    SkipSpace();
    if (pos_ != text_.size()) Fail("text after the JSON value");
  }

 private:
  [[noreturn]] void Fail(const std::string& reason) const {
    size_t line = 1, column = 1;
    for (size_t i = 0; i < pos_ && i < text_.size(); ++i) {
      if (text_[i] == '\n') {
        ++line;
        column = 1;
      } else {
        ++column;
      }
    }
    throw SpecError(std::string(source_),
                    fmt::format("invalid {} at line {}, column {}: {}; allowed: one JSON value "
                                "(RFC 8259: double-quoted strings and names, no trailing commas, "
                                "no comments) nested at most {} levels",
                                kind_, line, column, reason, max_depth_),
                    0);
  }

  bool AtEnd() const { return pos_ >= text_.size(); }
  char Peek() const { return AtEnd() ? '\0' : text_[pos_]; }

  void SkipSpace() {
    while (!AtEnd() && (text_[pos_] == ' ' || text_[pos_] == '\t' || text_[pos_] == '\n' ||
                        text_[pos_] == '\r')) {
      ++pos_;
    }
  }

  // Any value; containers are walked iteratively with `open_` as the stack.
  void Value() {
    std::vector<char> open;  // '[' or '{' per open container
    for (;;) {
      SkipSpace();
      const char c = Peek();
      if (c == '[' || c == '{') {
        if (static_cast<int>(open.size()) >= max_depth_) {
          Fail("nested deeper than " + std::to_string(max_depth_) + " levels");
        }
        ++pos_;
        open.push_back(c);
        SkipSpace();
        if (c == '{') {
          if (Peek() == '}') {
            ++pos_;
            open.pop_back();
          } else {
            Member();
            continue;  // its value follows
          }
        } else if (Peek() == ']') {
          ++pos_;
          open.pop_back();
        } else {
          continue;  // the first element follows
        }
      } else if (c == '"') {
        String();
      } else if (c == '-' || (c >= '0' && c <= '9')) {
        Number();
      } else if (Literal("true") || Literal("false") || Literal("null")) {
      } else {
        Fail(AtEnd() ? "the text ends where a value was expected"
                     : fmt::format("unexpected character {} where a value was expected", Shown(c)));
      }
      // After a complete value: close containers or move to the next element / member.
      for (;;) {
        if (open.empty()) return;
        SkipSpace();
        const char close = open.back() == '[' ? ']' : '}';
        if (Peek() == close) {
          ++pos_;
          open.pop_back();
          continue;
        }
        if (Peek() != ',') {
          Fail(AtEnd() ? "the text ends inside an array or object"
                       : fmt::format("expected ',' or '{}', found {}", close, Shown(Peek())));
        }
        ++pos_;
        SkipSpace();
        if (Peek() == ']' || Peek() == '}') Fail("a trailing comma");
        if (open.back() == '{') Member();
        break;
      }
    }
  }

  // "name" : (the value is parsed by the caller)
  void Member() {
    SkipSpace();
    if (Peek() != '"') {
      Fail(fmt::format("expected a double-quoted member name, found {}", Shown(Peek())));
    }
    String();
    SkipSpace();
    if (Peek() != ':')
      Fail(fmt::format("expected ':' after a member name, found {}", Shown(Peek())));
    ++pos_;
  }

  void String() {
    ++pos_;  // opening quote
    while (!AtEnd()) {
      const auto c = static_cast<unsigned char>(text_[pos_]);
      if (c == '"') {
        ++pos_;
        return;
      }
      if (c < 0x20) Fail("a control character inside a string (escape it)");
      if (c == '\\') {
        ++pos_;
        const char e = Peek();
        if (e == 'u') {
          for (int i = 1; i <= 4; ++i) {
            const char h = pos_ + i < text_.size() ? text_[pos_ + i] : '\0';
            if (!std::isxdigit(static_cast<unsigned char>(h))) Fail("a bad \\u escape");
          }
          pos_ += 5;
          continue;
        }
        if (e != '"' && e != '\\' && e != '/' && e != 'b' && e != 'f' && e != 'n' && e != 'r' &&
            e != 't') {
          Fail("a bad escape sequence");
        }
      }
      ++pos_;
    }
    Fail("an unterminated string");
  }

  // -? (0 | [1-9][0-9]*) (. [0-9]+)? ([eE] [-+]? [0-9]+)?
  void Number() {
    if (Peek() == '-') ++pos_;
    if (Peek() == '0') {
      ++pos_;
    } else if (Peek() >= '1' && Peek() <= '9') {
      while (Peek() >= '0' && Peek() <= '9') ++pos_;
    } else {
      Fail("a malformed number");
    }
    if (Peek() == '.') {
      ++pos_;
      if (!(Peek() >= '0' && Peek() <= '9')) Fail("a malformed number");
      while (Peek() >= '0' && Peek() <= '9') ++pos_;
    }
    if (Peek() == 'e' || Peek() == 'E') {
      ++pos_;
      if (Peek() == '+' || Peek() == '-') ++pos_;
      if (!(Peek() >= '0' && Peek() <= '9')) Fail("a malformed number");
      while (Peek() >= '0' && Peek() <= '9') ++pos_;
    }
  }

  bool Literal(std::string_view word) {
    if (text_.substr(pos_, word.size()) != word) return false;
    pos_ += word.size();
    return true;
  }

  static std::string Shown(char c) {
    if (c == '\0') return "the end of the text";
    const auto u = static_cast<unsigned char>(c);
    if (u < 0x20 || u >= 0x7F) return fmt::format("byte 0x{:02X}", u);
    return fmt::format("'{}'", c);
  }

  std::string_view text_;
  std::string_view source_;
  std::string_view kind_;
  int max_depth_;
  size_t pos_ = 0;
};

}  // namespace

void CheckJsonSyntax(std::string_view text, std::string_view source, std::string_view kind,
                     int max_depth) {
  JsonSyntax(text, source, kind, max_depth).Check();
}

}  // namespace driftlab::app
