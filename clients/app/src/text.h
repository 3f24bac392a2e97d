// Small text helpers the application layer's parts share (private to driftlab_app).
#pragma once

#include <charconv>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

namespace driftlab::app {

// The items separated by `separator`.
inline std::string Join(const std::vector<std::string>& items, std::string_view separator) {
  std::string out;
  for (const std::string& item : items) {
    if (!out.empty()) out += separator;
    out += item;
  }
  return out;
}

// Parses the whole of `text` as a number (std::from_chars: no blanks, no leading '+'); false for
// an empty text or anything after the number.
inline bool ParseWholeNumber(std::string_view text, double* value) {
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), *value);
  return !text.empty() && ec == std::errc() && ptr == text.data() + text.size();
}

}  // namespace driftlab::app
