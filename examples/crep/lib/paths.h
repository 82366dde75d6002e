// File paths given on the command line, checked before a command does any work: an input that is a
// directory, an output that cannot be created or that would overwrite an input or another output fail
// before anything is read or written. Command-line mistakes (an empty path, an output that is an input)
// are UsageErrors (exit 2), paths the file system refuses are IoErrors (exit 1); commands check the
// former first.
//
// The output rule (docs/TOOL.md, "Outputs"; the file-level rule is crep/support/output_file.h):
// every output of a command is checked before any of them is written and before any GL work (a symbolic
// link is followed to its final target, which is replaced and the link kept; a directory, device, FIFO or
// socket is refused; its directory must exist and accept a new file; an --export-frame folder is created
// then, and removed again if the command fails); every output is then written to a temporary file next to
// its target, and only when all are written are they renamed over their targets (OutputFiles). A command
// that fails leaves no output and no temporary behind.
#pragma once

#include <crep/support/output_file.h>

#include <filesystem>
#include <functional>
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

/// An input file: IoError "<option>: '<path>' is a directory, not a file" for a directory. With
/// `regularOnly` (EXR inputs, read at random positions) also for a FIFO, socket or device, which would block
/// or never end. A missing or unreadable file is left to the reader, which names the path.
void requireInputFile(const PathOption& input, bool regularOnly = false);

/// A file the command will write: UsageError naming the option for an empty path; IoError naming the
/// option and the path when it is a directory (or ends with '/'), a device, a FIFO or a socket (itself or
/// the final target of its symbolic links), when its directory does not exist, or when no file can be
/// created there (a temporary is created and removed to find out).
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

/// Every file one command writes, all or nothing (the output rule above). Register every output first
/// (addDirectory, addFile: the checks), do the work, write each output (write: into a temporary next to
/// its target), then commit() (the renames). Without a successful commit() the destructor removes every
/// temporary and the folders addDirectory created; if a rename fails, commit() also removes the outputs
/// it already renamed, so a failed command leaves no output of its own.
class OutputFiles {
public:
  OutputFiles() = default;
  OutputFiles(const OutputFiles&) = delete;
  OutputFiles& operator=(const OutputFiles&) = delete;
  ~OutputFiles();

  /// requireOutputFile, then registers the file.
  void addFile(const PathOption& output);
  /// requireOutputDirectory, then creates the folder (and missing parents) now: a folder that cannot be
  /// created fails before any work (IoError naming the option). Removed again by a failed command.
  void addDirectory(const PathOption& directory);
  /// Writes the registered output `path` (as given to addFile): `write` fills the temporary it is given.
  /// Exceptions propagate (the temporary is removed); IoError naming the option when the temporary cannot
  /// be created.
  void write(const std::string& path, const std::function<void(const std::filesystem::path&)>& write);
  /// Renames every written temporary over its target, in registration order. Throws (after removing what
  /// it renamed) on failure, or when a registered output was not written (a bug: logic_error).
  void commit();

private:
  struct Entry {
    PathOption output;
    PendingOutput pending;
  };
  std::vector<Entry> entries_;
  std::vector<std::filesystem::path> renamed_;     ///< targets commit() has replaced
  std::vector<std::filesystem::path> directories_; ///< created by addDirectory, outermost first
  bool committed_ = false;
  void rollback() noexcept;
};

} // namespace crep::tool
