// HTML building blocks of the web pages: escaping, the page frame, times, durations, and a JSON
// text shown as a collapsible tree. Every piece of text from a job, a result, a request or the
// store passes through Escape before it reaches a page.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace driftlab::server::web {

// & < > " ' escaped for HTML text and attribute values (app::EscapeHtml).
std::string Escape(std::string_view text);

// Percent-encoding of a URL query value (RFC 3986 unreserved characters kept).
std::string UrlEncode(std::string_view text);

// What the frame of a signed-in page shows: who is signed in and the form token of sign-out.
struct Viewer {
  std::string owner;
  std::string csrf;
  bool signed_in = true;  // false: the sign-in page (no navigation)
};

// A whole page: doctype, head (title, the embedded stylesheet and script, no external resource),
// the navigation bar (Jobs, Calibrations, Catalogue, the owner and a sign-out button) and `body`.
// `section` marks the current navigation entry ("jobs", "calibrations", "catalog").
std::string Page(const std::string& title, const std::string& section, const Viewer& viewer,
                 const std::string& body, const std::string& head_extra = "");

// "2024-05-01 12:34:56 UTC" from Unix seconds; "–" when absent.
std::string FormatUtc(std::optional<double> unix_s);
// "45 s", "12 min 05 s", "3 h 02 min", "2 d 04 h" (rounded down to the shown unit).
std::string FormatDuration(double seconds);
// 1234567 -> "1 234 567" (thin spaces between groups of three).
std::string FormatCount(uint64_t value);

// A JSON text (as protobuf prints it) as nested <details> elements: objects and arrays collapse,
// scalars show as key: value. Only the first levels up to `open_depth` start open. Escapes every
// key and value; text that is not JSON is shown as escaped preformatted text.
std::string JsonTree(std::string_view json, int open_depth = 1);

// A copyable shell command in a <pre class="cmd">.
std::string Command(const std::string& text);

}  // namespace driftlab::server::web
