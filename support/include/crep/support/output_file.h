// The one output rule of every file the support writers and the crep tool write: symbolic links followed,
// anything but a regular file refused, a temporary renamed over the target. Rules 1-3:
// support/README.md, "crep/support/output_file.h".
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <string_view>

namespace crep {

/// Where a write to `path` lands: the final target of its symbolic links. Throws IoError naming `path`
/// (not a regular file, a broken or too long link chain, no target directory).
std::filesystem::path resolveOutputTarget(const std::filesystem::path& path);

/// A temporary file next to an output's target (rule 3), renamed over it by commit(), else removed.
class PendingOutput {
public:
  PendingOutput() = default;
  /// Resolves `path` and creates the temporary, empty; IoError naming `path` if it cannot be created.
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

  /// Renames the temporary over the target (rule 2 re-checked); IoError naming the path on failure.
  void commit();
  /// Removes the temporary (no-op when there is none).
  void discard() noexcept;

private:
  std::filesystem::path path_, target_, temporary_;
};

/// Writes `path` by the rule: `write` fills the temporary (its exceptions propagate), then the rename.
void writeOutputFile(const std::filesystem::path& path,
                     const std::function<void(const std::filesystem::path& temporary)>& write);

/// Writes `text` to `path` by the rule (CSV, JSON, SVG). IoError naming the path on failure.
void writeTextFile(const std::filesystem::path& path, std::string_view text);

} // namespace crep
