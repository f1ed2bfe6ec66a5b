// OutputSet: what --overwrite may replace, staging and commit, the lock held while a command runs, stale staging of killed ones.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>

#include "core/error.hpp"
#include "io/output_set.hpp"
#include "support/temp_dir.hpp"

using namespace terrapolis;
using terrapolis::test::TempDir;
namespace fs = std::filesystem;

namespace {
void put(const fs::path& p, const std::string& text) { std::ofstream(p) << text; }
std::string get(const fs::path& p) {
  std::ifstream in(p);
  return std::string(std::istreambuf_iterator<char>(in), {});
}
/// The exit code of `f`'s ErrorKind: 2 for bad input, 1 for a processing error, 0 when it does not throw.
template <class F>
int exit_code_of(F f) {
  try {
    f();
  } catch (const Error& e) {
    return e.exit_code();
  }
  return 0;
}
}  // namespace

TEST(OutputSet, NewFolderAppearsOnlyAtCommitWithItsManifest) {
  TempDir dir;
  const fs::path out = dir.path() / "out";
  {
    OutputSet outputs("test", {}, false);
    const fs::path staging = outputs.folder(out.string());
    put(staging / "a.txt", "new");
    EXPECT_FALSE(fs::exists(out));
    outputs.commit();
  }
  EXPECT_EQ(get(out / "a.txt"), "new");
  EXPECT_NE(get(out / kOutputsManifest).find("\"a.txt\""), std::string::npos);
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()), 1);  // no staging left
}

TEST(OutputSet, UncommittedLeavesTheOldFolderAndNoStaging) {
  TempDir dir;
  const fs::path out = dir.path() / "out";
  {
    OutputSet first("test", {}, false);
    put(first.folder(out.string()) / "a.txt", "old");
    first.commit();
  }
  {
    OutputSet second("test", {}, true);
    put(second.folder(out.string()) / "a.txt", "half-written");
  }  // a failure: never committed
  EXPECT_EQ(get(out / "a.txt"), "old");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()), 1);
}

TEST(OutputSet, OverwriteReplacesOnlyRecordedFiles) {
  TempDir dir;
  const fs::path out = dir.path() / "out";
  {
    OutputSet first("test", {}, false);
    const fs::path s = first.folder(out.string());
    put(s / "a.txt", "old a");
    put(s / "b.txt", "old b");
    first.commit();
  }
  put(out / "notes.txt", "the user's");
  {
    OutputSet second("test", {}, true);
    put(second.folder(out.string()) / "a.txt", "new a");
    second.commit();
  }
  EXPECT_EQ(get(out / "a.txt"), "new a");
  EXPECT_FALSE(fs::exists(out / "b.txt"));  // ours, not written any more
  EXPECT_EQ(get(out / "notes.txt"), "the user's");
  EXPECT_EQ(get(out / kOutputsManifest).find("notes.txt"), std::string::npos);
}

TEST(OutputSet, RefusesWhatItDidNotWrite) {
  TempDir dir;
  const fs::path mine = dir.path() / "mydata";
  fs::create_directory(mine);
  put(mine / "precious.txt", "keep");
  EXPECT_EQ(exit_code_of([&] { OutputSet("test", {}, false).folder(mine.string()); }), 2);
  EXPECT_EQ(exit_code_of([&] { OutputSet("test", {}, true).folder(mine.string()); }), 2);
  EXPECT_EQ(exit_code_of([&] { OutputSet("test", {}, true).file((mine / "precious.txt").string()); }), 2);
  EXPECT_EQ(exit_code_of([&] { OutputSet("test", {}, true).folder((dir.path() / "no" / "such").string()); }), 2);
  EXPECT_EQ(exit_code_of([&] { OutputSet("test", {}, true).folder(""); }), 2);
  EXPECT_EQ(exit_code_of([&] { OutputSet("test", {}, true).folder("/"); }), 2);
  EXPECT_EQ(exit_code_of([&] { OutputSet("test", {}, true).folder("."); }), 2);
  // A folder holding an input, at any depth, and an input itself.
  fs::create_directories(dir.path() / "a" / "b");
  put(dir.path() / "a" / "b" / "dem.tif", "dem");
  const std::string dem = (dir.path() / "a" / "b" / "dem.tif").string();
  EXPECT_EQ(exit_code_of([&] { OutputSet("test", {dem}, true).folder((dir.path() / "a").string()); }), 2);
  EXPECT_EQ(exit_code_of([&] { OutputSet("test", {dem}, true).file(dem); }), 2);
  EXPECT_EQ(get(mine / "precious.txt"), "keep");
  EXPECT_EQ(get(dem), "dem");
}

TEST(OutputSet, FileIsReplacedOnlyWhenRecorded) {
  TempDir dir;
  const fs::path f = dir.path() / "out.txt";
  {
    OutputSet outputs("test", {}, false);
    put(outputs.file(f.string()), "one");
    outputs.commit();
  }
  EXPECT_EQ(exit_code_of([&] { OutputSet("test", {}, false).file(f.string()); }), 2);  // exists, no --overwrite
  {
    OutputSet outputs("test", {}, true);
    put(outputs.file(f.string()), "two");
    outputs.commit();
  }
  EXPECT_EQ(get(f), "two");
}

TEST(OutputSet, RemovesStagingOfEndedCommandsOnly) {
  TempDir dir;
  const fs::path out = dir.path() / "out";
  const fs::path dead = dir.path() / "out.tmp-999999";      // marked, and no command holds out's lock
  const fs::path unmarked = dir.path() / "out.tmp-1";       // no marker: not ours
  for (const auto& p : {dead, unmarked}) fs::create_directory(p);
  put(dead / ".terrapolis-staging", "test\n");
  {
    OutputSet live("test", {}, false);
    const fs::path staging = live.folder(out.string());
    EXPECT_FALSE(fs::exists(dead));
    EXPECT_TRUE(fs::exists(unmarked));
    // A second command on the same output, while the first holds it: refused, its staging untouched.
    OutputSet second("test", {}, false);
    try {
      second.folder(out.string());
      ADD_FAILURE() << "a second command on a held output was not refused";
    } catch (const Error& e) {
      EXPECT_EQ(e.exit_code(), 2);
      EXPECT_NE(std::string(e.what()).find("another terrapolis command (pid " + std::to_string(getpid()) + ") is writing this output"),
                std::string::npos)
          << e.what();
    }
    EXPECT_TRUE(fs::exists(staging / ".terrapolis-staging"));
    put(staging / "a.txt", "a");
    live.commit();
  }
  EXPECT_EQ(get(out / "a.txt"), "a");
  EXPECT_FALSE(fs::exists(dir.path() / ".out.terrapolis-lock"));  // released and removed
  {
    OutputSet next("test", {}, true);  // the output is free again
    put(next.folder(out.string()) / "a.txt", "b");
    next.commit();
  }
  EXPECT_EQ(get(out / "a.txt"), "b");
}

TEST(OutputSet, NewOutputNeverReplacesOneThatAppeared) {
  TempDir dir;
  const fs::path out = dir.path() / "out";
  OutputSet outputs("test", {}, false);
  put(outputs.folder(out.string()) / "a.txt", "ours");
  fs::create_directory(out);
  put(out / "theirs.txt", "theirs");  // made by something else while the command ran
  EXPECT_EQ(exit_code_of([&] { outputs.commit(); }), 2);
  EXPECT_EQ(get(out / "theirs.txt"), "theirs");
  EXPECT_FALSE(fs::exists(out / "a.txt"));
}
