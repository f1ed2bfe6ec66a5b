// The outputs of one command, folders and files, under one safety contract (docs/safety.md).
// SPDX-License-Identifier: MIT
#pragma once
#include <filesystem>
#include <string>
#include <vector>

namespace terrapolis {

/// Every command declares its outputs here before any work, writes them where this class says,
/// and calls commit() at the end:
/// - refused at declaration (bad_input, exit 2): an empty path, a missing parent folder, an
///   existing output without --overwrite; with it, `/`, the home folder, the current folder or one
///   of their ancestors, an input or a folder holding one (at any depth), and a folder or file
///   terrapolis did not write (not recorded in its folder's manifest, `.terrapolis-outputs.json`);
/// - written beside their final place, in staging folders "<output>.tmp-<pid>", and moved in place
///   only by commit(): a failed or interrupted command leaves the previous outputs as they were and
///   no temporary file behind (the destructor removes the staging folders);
/// - commit() replaces only the files the manifest records (the previous command's) and records the
///   new ones; files a user added to an output folder stay;
/// - reserved at declaration: each output has a lock file beside it, ".<name>.terrapolis-lock",
///   held (flock) until the command ends, so that of two commands writing the same output the
///   second is refused at once (bad_input, naming the output and the first command's pid); a new
///   output is moved in place by a rename that never replaces what appeared meanwhile;
/// - staging folders of the same output left by commands that died (SIGKILL, power loss: their
///   lock is free) are removed at declaration, with a warning naming them.
class OutputSet {
 public:
  /// `inputs`: every file or folder the command reads; `overwrite`: --overwrite was given.
  OutputSet(std::string command, std::vector<std::string> inputs, bool overwrite);
  ~OutputSet();
  OutputSet(const OutputSet&) = delete;
  OutputSet& operator=(const OutputSet&) = delete;

  /// Declares an output folder; returns the (staging) folder to write its files into. With
  /// `keep_files`, the staging folder starts with a copy of the folder's recorded files (a rerun
  /// that keeps some of them).
  std::filesystem::path folder(const std::string& dir, bool keep_files = false);
  /// Declares an output file; returns the path to write it to (in a staging folder, same name).
  std::string file(const std::string& path);

  /// Moves every output in place and records it in its folder's manifest. Checks first that no
  /// interrupt arrived, so that an interrupted command never replaces anything.
  void commit();

 private:
  struct Target {
    std::filesystem::path final_path, staging;
    bool is_folder = false;
  };
  /// A held reservation of one output: the lock file and its descriptor.
  struct Lock {
    std::filesystem::path path;
    int fd = -1;
  };
  void reserve(const std::filesystem::path& abs, const std::string& name);
  void check_target(const std::filesystem::path& path, bool is_folder);
  std::filesystem::path make_staging(const std::filesystem::path& path);
  void commit_folder(const Target& t) const;
  void commit_file(const Target& t) const;

  std::string command_;
  std::vector<std::filesystem::path> inputs_;  ///< absolute, canonical
  bool overwrite_;
  std::vector<Target> targets_;
  std::vector<Lock> locks_;
  bool committed_ = false;
};

/// `message` with every staging folder of this process replaced by the output it stands for, as
/// the user wrote it ("/abs/h.tmp-42/filled.tif" reads "h/filled.tif"): errors name the outputs.
std::string with_output_names(std::string message);

/// The name of the manifest an output folder holds (the files a command wrote in it).
inline constexpr const char* kOutputsManifest = ".terrapolis-outputs.json";

}  // namespace terrapolis
