// Bounded reading of input files (input_files.h).
#include "driftlab/input_files.h"

#include <cerrno>
#include <cstring>
#include <sstream>
#include <system_error>

#include "driftlab/spec_error.h"

namespace driftlab {
namespace {

std::string Kind(std::filesystem::file_type type) {
  switch (type) {
    case std::filesystem::file_type::directory:
      return "a directory";
    case std::filesystem::file_type::character:
      return "a character device";
    case std::filesystem::file_type::block:
      return "a block device";
    case std::filesystem::file_type::fifo:
      return "a FIFO";
    case std::filesystem::file_type::socket:
      return "a socket";
    default:
      return "not a regular file";
  }
}

std::string MiB(uint64_t bytes) {
  std::ostringstream out;
  out << static_cast<double>(bytes) / (1 << 20) << " MiB";
  return out.str();
}

// "FIELD: 'PATH': what; allowed: ..." (the path is left out when it is the field itself).
[[noreturn]] void Refuse(const std::string& field, const std::filesystem::path& path,
                         const std::string& what, const std::string& allowed) {
  const std::string subject = field == path.string() ? "" : "'" + path.string() + "': ";
  throw SpecError(field, subject + what + "; allowed: " + allowed, 0);
}

}  // namespace

std::ifstream OpenInputFile(const std::filesystem::path& path, uint64_t max_bytes,
                            const std::string& field) {
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(path, ec);
  if (status.type() == std::filesystem::file_type::not_found) {
    Refuse(field, path, "no such file (cannot open it)", "an existing, readable file");
  }
  if (ec) Refuse(field, path, "cannot open it (" + ec.message() + ")", "a readable file");
  if (status.type() != std::filesystem::file_type::regular) {
    Refuse(field, path, Kind(status.type()), "a regular file");
  }
  const uint64_t size = std::filesystem::file_size(path, ec);
  if (ec) Refuse(field, path, "cannot open it (" + ec.message() + ")", "a readable file");
  if (size > max_bytes) {
    Refuse(field, path, std::to_string(size) + " bytes",
           "a file of at most " + std::to_string(max_bytes) + " bytes (" + MiB(max_bytes) + ")");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    Refuse(field, path, std::string("cannot open it (") + std::strerror(errno) + ")",
           "a readable file");
  }
  return in;
}

std::string ReadInputFile(const std::filesystem::path& path, uint64_t max_bytes,
                          const std::string& field) {
  std::ifstream in = OpenInputFile(path, max_bytes, field);
  std::string text;
  char buffer[1 << 16];
  while (in.read(buffer, sizeof buffer) || in.gcount() > 0) {
    text.append(buffer, static_cast<size_t>(in.gcount()));
    // The file may have grown since its size was checked.
    if (text.size() > max_bytes) {
      Refuse(field, path, "more than " + std::to_string(max_bytes) + " bytes",
             "a file of at most " + std::to_string(max_bytes) + " bytes");
    }
  }
  if (in.bad()) Refuse(field, path, "a read error", "a readable file");
  return text;
}

bool ReadLine(std::istream& in, std::string* line, const std::string& where, size_t max_bytes) {
  line->clear();
  std::streambuf* buf = in.rdbuf();
  bool any = false;
  for (;;) {
    const int c = buf->sbumpc();
    if (c == std::char_traits<char>::eof()) {
      in.setstate(std::ios::eofbit);
      break;
    }
    any = true;
    if (c == '\n') break;
    if (line->size() == max_bytes) {
      throw SpecError(where,
                      "a line longer than " + std::to_string(max_bytes) +
                          " bytes; allowed: lines of at most " + std::to_string(max_bytes) +
                          " bytes",
                      0);
    }
    line->push_back(static_cast<char>(c));
  }
  if (!line->empty() && line->back() == '\r') line->pop_back();
  return any;
}

bool YamlQuotedScalarIsClosed(std::string_view text, size_t start) {
  if (start >= text.size()) return false;
  const char quote = text[start];
  if (quote != '"' && quote != '\'') return true;  // not a quoted scalar
  for (size_t i = start + 1; i < text.size(); ++i) {
    if (quote == '"' && text[i] == '\\') {
      ++i;  // the escaped character
    } else if (text[i] == quote) {
      if (quote == '\'' && i + 1 < text.size() && text[i + 1] == '\'') {
        ++i;  // '' inside single quotes
      } else {
        return true;
      }
    }
  }
  return false;
}

}  // namespace driftlab
