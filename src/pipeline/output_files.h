// Result files written safely: the output folder made and tested before any work (a folder
// that cannot be written is found before meshing, not after SIMP), and every file written
// to a temporary name in its folder and renamed over the final name, so that a reader never
// sees half a file and a symlink at the final name is replaced, never followed.
#pragma once
#include <functional>
#include <string>

namespace topopt::pipeline {

/// Creates `dir` (and its parents) and checks that a file can be created in it. `setting`
/// names how the user chose the folder ("'output.directory' or --out-dir"). Throws
/// Error(Io) naming the folder, the reason and the setting to change.
void prepare_output_folder(const std::string& dir, const std::string& setting);

/// Writes the file `path` by calling write(temporary) with a fresh file of a temporary name
/// in the same folder, then renames it to `path`. The temporary file is removed if write
/// throws. Returns `path`. Throws Error(Io) naming `path` if the rename fails.
std::string write_replacing(const std::string& path, const std::function<void(const std::string& temporary)>& write);

}  // namespace topopt::pipeline
