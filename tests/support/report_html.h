// Helpers for the HTML-report tests: the reports inline dygraphs and report_plots.js
// in <script> elements, whose JavaScript text is not markup; the tests check the markup around it.
#pragma once

#include <string>

namespace driftlab::testing {

// How often `part` occurs in `text` (overlapping occurrences counted).
inline size_t Count(const std::string& text, const std::string& part) {
  size_t n = 0;
  for (size_t at = text.find(part); at != std::string::npos; at = text.find(part, at + 1)) ++n;
  return n;
}

// `html` with the text of every <script> element removed (the <script> and </script> tags kept).
inline std::string WithoutScriptText(const std::string& html) {
  std::string out;
  size_t at = 0;
  while (true) {
    const size_t open = html.find("<script", at);
    if (open == std::string::npos) break;
    const size_t body = html.find('>', open);
    const size_t close = html.find("</script>", body);
    if (body == std::string::npos || close == std::string::npos) break;
    out.append(html, at, body + 1 - at);
    at = close;
  }
  return out + html.substr(at);
}

// Occurrences of `part` in `text`.
inline size_t Occurrences(const std::string& text, const std::string& part) {
  size_t n = 0;
  for (size_t at = text.find(part); at != std::string::npos; at = text.find(part, at + 1)) ++n;
  return n;
}

}  // namespace driftlab::testing
