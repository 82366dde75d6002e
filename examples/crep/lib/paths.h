// File paths given on the command line, checked before a command does any work: an input that is a
// directory, an output that cannot be created or that would overwrite an input or another output fail
// before anything is read or written. Command-line mistakes (an empty path, an output that is an input)
// are UsageErrors (exit 2), paths the file system refuses are IoErrors (exit 1); commands check the
// former first.
#pragma once

#include <string>
#include <vector>

namespace crep::tool {

/// A path and the option that gave it ("--out").
struct PathOption {
  std::string option;
  std::string path;
};

/// UsageError "option <option>: must not be empty" for an empty path.
void requireNonEmpty(const PathOption& path);

/// An input file: IoError "<option>: '<path>' is a directory, not a file" for a directory. A missing
/// or unreadable file is left to the reader, which names the path.
void requireInputFile(const PathOption& input);

/// A file the command will write: UsageError naming the option for an empty path; IoError naming the
/// option and the path when it is a directory (or ends with '/') or its parent directory does not exist.
void requireOutputFile(const PathOption& output);

/// A directory the command writes into, created if missing: UsageError for an empty path; IoError naming
/// the option when it, or the nearest of its ancestors that exists, is not a directory.
void requireOutputDirectory(const PathOption& directory);

/// An output prefix (PREFIX.exr, PREFIX.png): UsageError naming the option when it is empty or ends in
/// a directory ("out/", "out/.", ".."), which would write hidden files such as "out/.exr".
void requireOutputPrefix(const PathOption& prefix);

/// Every output differs from every input and from the other outputs (same file after resolving ".",
/// "..", symbolic links and hard links): UsageError naming the option otherwise, as writing it would
/// overwrite the input or the other output.
void requireDistinctFiles(const std::vector<PathOption>& outputs, const std::vector<PathOption>& inputs = {});

} // namespace crep::tool
