// Reading input files within limits (DESIGN.md invariant 10): every reader checks, before
// the work, that its input is a regular file (not a directory, a device such as /dev/zero, a FIFO)
// of bounded size, and reads it line by line with a bounded line length, so no input file can make
// a reader run forever or exhaust memory. Exceeding a limit is a SpecError naming the file, what
// was found and the limit.
#pragma once

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <istream>
#include <string>
#include <string_view>

namespace driftlab {

// Size limits of each kind of input file [bytes]. Generous for real data: a 10-hour 100 Hz
// 7-column recording is ~0.3 GB of CSV; a job file of 20 000 epochs ~0.5 MB.
inline constexpr uint64_t kMaxJobFileBytes = 16ull << 20;        // job files (JSON / YAML)
inline constexpr uint64_t kMaxSmallTextFileBytes = 1ull << 20;   // datasheets, gate rules, tokens
inline constexpr uint64_t kMaxMotionFileBytes = 256ull << 20;    // motion / truth-profile CSV
inline constexpr uint64_t kMaxRecordingFileBytes = 16ull << 30;  // sensor recordings (CSV)
inline constexpr uint64_t kMaxResultFileBytes = 4ull << 30;      // result JSON files
inline constexpr size_t kMaxLineBytes = 1 << 20;                 // one line of a text file

// Opens `path` for reading after checking that it is a regular file of at most max_bytes bytes
// (symbolic links are followed). Throws SpecError(field, ...) naming the path otherwise, or when
// it cannot be opened (with the system's reason).
std::ifstream OpenInputFile(const std::filesystem::path& path, uint64_t max_bytes,
                            const std::string& field);

// The whole content of `path`, with the checks of OpenInputFile.
std::string ReadInputFile(const std::filesystem::path& path, uint64_t max_bytes,
                          const std::string& field);

// Reads the next line of `in` (without its '\n' and a trailing '\r') into *line; false at the end
// of the input. A line longer than max_bytes is a SpecError(where, ...) before more of it is read;
// a read error is a SpecError too.
bool ReadLine(std::istream& in, std::string* line, const std::string& where,
              size_t max_bytes = kMaxLineBytes);

// yaml-cpp (0.7) ends a quoted scalar that is never closed at the end of the text instead of
// reporting it, so a missing quote would silently swallow the rest of a file into one value. For
// the quoted scalar whose opening quote (' or ") is at text[start], true when its closing quote
// exists (YAML 1.2 sections 7.3.1-7.3.2: \ escapes in double quotes, '' in single quotes).
bool YamlQuotedScalarIsClosed(std::string_view text, size_t start);

}  // namespace driftlab
