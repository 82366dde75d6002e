#include "paths.h"

#include "args.h"

#include <crep/core/error.h>

#include <filesystem>
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

void requireInputFile(const PathOption& input) {
  std::error_code ec;
  if (fs::is_directory(input.path, ec))
    throw IoError(input.option + ": '" + input.path + "' is a directory, not a file");
}

void requireOutputFile(const PathOption& output) {
  requireNonEmpty(output);
  const fs::path p(output.path);
  std::error_code ec;
  if (!p.has_filename() || fs::is_directory(p, ec))
    throw IoError(output.option + ": cannot write '" + output.path + "': it is a directory, not a file");
  const fs::path parent = p.parent_path();
  if (!parent.empty() && !fs::is_directory(parent, ec))
    throw IoError(output.option + ": cannot write '" + output.path + "': directory '" + parent.string() +
                  "' does not exist");
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

} // namespace crep::tool
