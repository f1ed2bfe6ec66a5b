// An output folder of a command: refuse clobbering before any work, create the folder only to write.
// SPDX-License-Identifier: MIT
#pragma once
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

#include "core/error.hpp"
#include "io/raster_io.hpp"

namespace terrapolis::cli {

/// The files a command writes into one folder. Checks them up front (so a run that would be
/// refused fails before computing), creates the folder when writing starts, and removes what
/// this run wrote if a later file fails, so that no partial set of outputs is left.
class OutputDir {
 public:
  OutputDir(std::string dir, std::vector<std::string> names, bool overwrite) : dir_(std::move(dir)), overwrite_(overwrite) {
    std::error_code ec;
    if (std::filesystem::exists(dir_, ec) && !std::filesystem::is_directory(dir_, ec)) throw bad_input(dir_ + ": exists and is not a folder");
    for (const auto& name : names) {
      paths_.push_back((std::filesystem::path(dir_) / name).string());
      if (std::filesystem::exists(dir_, ec)) check_output_path(paths_.back(), overwrite_);
    }
  }

  const std::string& path(std::size_t i) const { return paths_.at(i); }

  /// Runs `write(path, overwrite)` for each file in order; on failure removes the files already written.
  template <class WriteFn>
  void write_all(WriteFn write) {
    std::error_code ec;
    std::filesystem::create_directories(dir_, ec);
    if (ec) throw bad_input(dir_ + ": cannot create the output folder (" + ec.message() + ")");
    std::size_t done = 0;
    try {
      for (; done < paths_.size(); ++done) write(done, paths_[done], overwrite_);
    } catch (...) {
      for (std::size_t i = 0; i < done; ++i) std::filesystem::remove(paths_[i], ec);
      throw;
    }
  }

 private:
  std::string dir_;
  bool overwrite_;
  std::vector<std::string> paths_;
};

}  // namespace terrapolis::cli
