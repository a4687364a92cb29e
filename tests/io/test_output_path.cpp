// The checks CLIs make of their output paths before long work, and the output folder lock.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <unistd.h>

#include "panmap/core/error.h"
#include "panmap/io/output_path.h"
#include "test_helpers.h"

namespace panmap {
namespace {

namespace fs = std::filesystem;

TEST(OutputPath, FilesAndFoldersThatCannotBeWrittenAreNamed) {
  test::TempDir dir;
  std::ofstream(dir.path("file")) << "x";
  EXPECT_NO_THROW(checkOutputFile(dir.path("new.json"), "--out"));
  EXPECT_NO_THROW(checkOutputFile(dir.path("file"), "--out"));  // replaced, and writable
  EXPECT_FALSE(fs::exists(dir.path("new.json")));               // nothing created
  test::expectError([&] { checkOutputFile(dir.path(), "--trajectory-out"); },
                    {"--trajectory-out " + dir.path(), "is a folder, not a file"});
  test::expectError([&] { checkOutputFile(dir.path("none/x.json"), "--out"); },
                    {"folder " + dir.path("none") + " does not exist"});
  EXPECT_NO_THROW(checkOutputFolder(dir.path("a/b"), "--out"));
  test::expectError([&] { checkOutputFolder(dir.path("file/map"), "--out"); },
                    {dir.path("file") + " is a file, not a folder"});
}

// Two mappers writing one --out mixed their autosave journals, and a resume took the other's
// snapshot; the second is now refused, naming the first.
TEST(OutputPath, ASecondWriterOfAFolderIsRefusedNamingTheFirst) {
  test::TempDir dir;
  const std::string out = dir.path("out");
  {
    OutputFolderLock first(out);
    EXPECT_TRUE(fs::is_directory(out));
    test::expectError([&] { OutputFolderLock second(out); },
                      {"output folder " + out + " is in use by another panmap process",
                       "(pid " + std::to_string(::getpid()) + ")"});
  }
  // Released with its holder; a folder it created and left empty is gone again.
  EXPECT_FALSE(fs::exists(out));
  fs::create_directory(out);
  std::ofstream(out + "/map.panmap") << "x";
  { OutputFolderLock again(out); }
  EXPECT_TRUE(fs::exists(out + "/map.panmap"));
  EXPECT_FALSE(fs::exists(out + "/.panmap.lock"));
}

}  // namespace
}  // namespace panmap
