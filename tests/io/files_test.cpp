#include "io/files.hpp"

#include "io/test_files.hpp"

#include <gtest/gtest.h>

namespace jointid::io {
namespace {

namespace fs = std::filesystem;

TEST(WriteFileAtomically, WritesAndReplacesWholeFiles) {
  test::TempDir dir;
  const fs::path path = dir / "out.txt";
  write_file_atomically(path, "first\n");
  EXPECT_EQ(test::read_text(path), "first\n");
  write_file_atomically(path, "second, longer content\n");
  EXPECT_EQ(test::read_text(path), "second, longer content\n");
  write_file_atomically(path, "");
  EXPECT_EQ(test::read_text(path), "");
  // No temporary files are left behind.
  int files = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir.path()))
    ++files;
  EXPECT_EQ(files, 1);
}

TEST(WriteFileAtomically, FailureNamesThePathAndKeepsNothing) {
  test::TempDir dir;
  const fs::path path = dir / "missing_dir" / "out.txt";
  try {
    write_file_atomically(path, "x");
    FAIL() << "expected io::Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(path));
  // A directory in the way is refused, not replaced.
  fs::create_directories(dir / "taken");
  EXPECT_THROW(write_file_atomically(dir / "taken", "x"), Error);
  EXPECT_TRUE(fs::is_directory(dir / "taken"));
}

TEST(ReadFile, ReadsBytesAndNamesMissingFiles) {
  test::TempDir dir;
  test::write_text(dir / "a.txt", std::string("a\0b\r\n", 5));
  EXPECT_EQ(read_file(dir / "a.txt"), std::string("a\0b\r\n", 5));
  try {
    read_file(dir / "nothing.csv");
    FAIL() << "expected io::Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("nothing.csv"), std::string::npos) << e.what();
  }
}

} // namespace
} // namespace jointid::io
