// The one rule for every file the support writers (writeExr, writeExrLayers, writePng, writeTextFile) and
// the crep tool write (docs/TOOL.md, "Outputs"):
//
//   1. A path that is a symbolic link (a chain of them) is followed to its final target: the target is
//      replaced and the links stay. A dangling link creates its target.
//   2. A path (or final target) that exists and is not a regular file is refused with IoError naming it:
//      a directory, a character or block device (/dev/null), a FIFO, a socket. Nothing is written.
//   3. The content is written to a temporary file in the target's directory ("<target>.crep-XXXXXX.partial",
//      created exclusively; an existing target's permission bits are kept, a new file gets 0666 & ~umask)
//      and renamed over the target: a reader never sees a partial file, and a failure (full disk, I/O
//      error, exception) removes the temporary and leaves the target as it was.
//
// PendingOutput is the rule's building block for commands that write several files all or nothing: each
// file is written to its temporary, and only when every one is written are they renamed (commit()).
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <string_view>

namespace crep {

/// Where a write to `path` lands under the rule above: the final target of its symbolic links (the path
/// itself when it is no link). Throws IoError naming `path` when it or its target exists and is not a
/// regular file, when a link chain is longer than 40 or cannot be read, or when the target's directory does
/// not exist or is not a directory.
std::filesystem::path resolveOutputTarget(const std::filesystem::path& path);

/// A temporary file next to an output's target (rule 3), renamed over the target by commit(); removed by
/// discard() or the destructor when not committed.
class PendingOutput {
public:
  PendingOutput() = default;
  /// Resolves `path` (resolveOutputTarget) and creates the temporary, empty. IoError naming `path` when the
  /// temporary cannot be created (no permission, read-only file system, ...).
  explicit PendingOutput(const std::filesystem::path& path);
  PendingOutput(PendingOutput&& other) noexcept;
  PendingOutput& operator=(PendingOutput&& other) noexcept;
  PendingOutput(const PendingOutput&) = delete;
  PendingOutput& operator=(const PendingOutput&) = delete;
  ~PendingOutput();

  const std::filesystem::path& path() const noexcept { return path_; }           ///< as given
  const std::filesystem::path& target() const noexcept { return target_; }       ///< where it lands
  const std::filesystem::path& temporary() const noexcept { return temporary_; } ///< write here
  bool pending() const noexcept { return !temporary_.empty(); } ///< a temporary exists, not committed

  /// Renames the temporary over the target (re-checking rule 2 first). IoError naming the path on failure
  /// (the temporary is then removed).
  void commit();
  /// Removes the temporary (no-op when there is none).
  void discard() noexcept;

private:
  std::filesystem::path path_, target_, temporary_;
};

/// Writes `path` by the rule: `write` fills the temporary file it is given (any exception it throws
/// propagates after the temporary is removed), then the temporary is renamed over the target.
void writeOutputFile(const std::filesystem::path& path,
                     const std::function<void(const std::filesystem::path& temporary)>& write);

/// Writes `text` to `path` by the rule (CSV, JSON, SVG). IoError naming the path on failure.
void writeTextFile(const std::filesystem::path& path, std::string_view text);

} // namespace crep
