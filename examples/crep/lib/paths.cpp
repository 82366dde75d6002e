#include "paths.h"

#include "args.h"

#include <crep/core/error.h>

#include <filesystem>
#include <stdexcept>
#include <system_error>

namespace crep::tool {

namespace fs = std::filesystem;

namespace {

/// True if `a` and `b` name the same file: equivalent() for existing files (hard links too), else the
/// same weakly canonical path (symbolic links, "." and ".." resolved as far as the path exists).
bool sameFile(const std::string& a, const std::string& b) {
  std::error_code ec;
  if (fs::exists(a, ec) && fs::exists(b, ec)) {
    const bool same = fs::equivalent(a, b, ec);
    if (!ec) return same;
  }
  std::error_code eca, ecb;
  const fs::path ca = fs::weakly_canonical(fs::absolute(a, eca), eca);
  const fs::path cb = fs::weakly_canonical(fs::absolute(b, ecb), ecb);
  if (eca || ecb) return fs::path(a).lexically_normal() == fs::path(b).lexically_normal();
  return ca == cb;
}

} // namespace

void requireNonEmpty(const PathOption& path) {
  if (path.path.empty()) throw UsageError("option " + path.option + ": must not be empty");
}

void requireInputFile(const PathOption& input, bool regularOnly) {
  std::error_code ec;
  const fs::file_status status = fs::status(input.path, ec);
  if (fs::is_directory(status))
    throw IoError(input.option + ": '" + input.path + "' is a directory, not a file");
  if (regularOnly && fs::exists(status) && !fs::is_regular_file(status))
    throw IoError(input.option + ": '" + input.path + "' is " +
                  (fs::is_fifo(status)     ? "a FIFO (named pipe)"
                   : fs::is_socket(status) ? "a socket"
                                           : "a device") +
                  ", not a regular file (an EXR file is read at random positions)");
}

void requireOutputFile(const PathOption& output) {
  requireNonEmpty(output);
  const fs::path p(output.path);
  std::error_code ec;
  if (!p.has_filename() || fs::is_directory(p, ec))
    throw IoError(output.option + ": cannot write '" + output.path +
                  "': it is a directory, not a regular file");
  // The rule of crep/support/output_file.h: links followed, non-regular files refused, the directory
  // exists; then a temporary created and removed proves that the directory takes a new file.
  try {
    PendingOutput probe(p);
  } catch (const IoError& e) {
    std::string what = e.what();
    if (what.starts_with("crep: ")) what = what.substr(6);
    throw IoError(output.option + ": " + what);
  }
}

void requireOutputDirectory(const PathOption& directory) {
  requireNonEmpty(directory);
  std::error_code ec;
  const fs::path p(directory.path);
  if (fs::exists(p, ec)) {
    if (!fs::is_directory(p, ec))
      throw IoError(directory.option + ": '" + directory.path + "' exists and is not a directory");
    return;
  }
  for (fs::path ancestor = p.parent_path(); !ancestor.empty(); ancestor = ancestor.parent_path()) {
    if (fs::exists(ancestor, ec)) {
      if (!fs::is_directory(ancestor, ec))
        throw IoError(directory.option + ": cannot create directory '" + directory.path + "': '" +
                      ancestor.string() + "' is not a directory");
      return;
    }
    if (ancestor == ancestor.parent_path()) break; // the root
  }
}

void requireOutputPrefix(const PathOption& prefix) {
  requireNonEmpty(prefix);
  const fs::path name = fs::path(prefix.path).filename();
  if (name.empty() || name == "." || name == "..")
    throw UsageError("option " + prefix.option + ": '" + prefix.path +
                     "' names a directory; the option takes a file name prefix such as 'out/frame'");
}

void requireDistinctFiles(const std::vector<PathOption>& outputs, const std::vector<PathOption>& inputs) {
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    const PathOption& out = outputs[i];
    for (const PathOption& in : inputs)
      if (sameFile(out.path, in.path))
        throw UsageError("option " + out.option + ": '" + out.path + "' is the input file of " + in.option +
                         " ('" + in.path + "'); refusing to overwrite it");
    for (std::size_t j = 0; j < i; ++j)
      if (sameFile(out.path, outputs[j].path))
        throw UsageError("option " + out.option + ": '" + out.path + "' is also written by " +
                         outputs[j].option + " ('" + outputs[j].path + "'); refusing to write it twice");
  }
}

OutputFiles::~OutputFiles() {
  if (!committed_) rollback();
}

void OutputFiles::addFile(const PathOption& output) {
  requireOutputFile(output);
  entries_.push_back({output, {}});
}

void OutputFiles::addDirectory(const PathOption& directory) {
  requireOutputDirectory(directory);
  // Create it level by level, remembering what this command created (removed again if it fails).
  std::vector<fs::path> missing;
  std::error_code ec;
  for (fs::path p = fs::path(directory.path); !p.empty() && !fs::exists(p, ec); p = p.parent_path()) {
    missing.push_back(p);
    if (p == p.parent_path()) break;
  }
  for (auto it = missing.rbegin(); it != missing.rend(); ++it) {
    if (!fs::create_directory(*it, ec) && ec)
      throw IoError(directory.option + ": cannot create directory '" + it->string() + "': " + ec.message());
    directories_.push_back(*it);
  }
  if (!fs::is_directory(directory.path, ec))
    throw IoError(directory.option + ": '" + directory.path + "' is not a directory");
}

void OutputFiles::write(const std::string& path, const std::function<void(const fs::path&)>& write) {
  for (Entry& e : entries_) {
    if (e.output.path != path) continue;
    try {
      e.pending = PendingOutput(e.output.path);
    } catch (const IoError& error) {
      std::string what = error.what();
      if (what.starts_with("crep: ")) what = what.substr(6);
      throw IoError(e.output.option + ": " + what);
    }
    try {
      write(e.pending.temporary());
    } catch (const IoError& error) {
      // Named by the option and the output's own path (the writer saw the temporary's).
      std::string what = error.what();
      if (what.starts_with("crep: ")) what = what.substr(6);
      // The writer named the temporary: name the output instead.
      const std::string temporary = e.pending.temporary().string();
      for (std::size_t at = what.find(temporary); !temporary.empty() && at != std::string::npos;
           at = what.find(temporary, at + e.output.path.size()))
        what.replace(at, temporary.size(), e.output.path);
      e.pending.discard();
      throw IoError(e.output.option + ": " + what);
    } catch (...) {
      e.pending.discard();
      throw;
    }
    return;
  }
  throw std::logic_error("OutputFiles::write: '" + path + "' was not registered with addFile");
}

void OutputFiles::commit() {
  for (const Entry& e : entries_)
    if (!e.pending.pending())
      throw std::logic_error("OutputFiles::commit: '" + e.output.path + "' was registered but not written");
  for (Entry& e : entries_) {
    try {
      e.pending.commit();
    } catch (const IoError& error) {
      std::string what = error.what();
      if (what.starts_with("crep: ")) what = what.substr(6);
      throw IoError(e.output.option + ": " + what);
    }
    renamed_.push_back(e.pending.target());
  }
  committed_ = true;
}

void OutputFiles::rollback() noexcept {
  for (Entry& e : entries_)
    e.pending.discard();
  std::error_code ec;
  for (const fs::path& target : renamed_)
    fs::remove(target, ec);
  for (auto it = directories_.rbegin(); it != directories_.rend(); ++it)
    fs::remove(*it, ec); // only when empty: a folder with files of others stays
}

} // namespace crep::tool
