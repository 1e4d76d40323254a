#include "io/files.hpp"

#include "io/test_files.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <csignal>
#include <unistd.h>

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

// Names in `dir`, sorted (temporary files are hidden ones: ".<name>.tmp.*").
std::vector<std::string> names_in(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir))
    names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

TEST(OutputFiles, AllOrNothing) {
  test::TempDir dir;
  test::write_text(dir / "a.csv", "old a\n");
  {
    OutputFiles out;
    out.add(dir / "a.csv", "new a\n");
    out.add(dir / "b.csv", "new b\n");
    // Not committed (a later step failed): both targets as they were, no temporary file left.
  }
  EXPECT_EQ(names_in(dir.path()), std::vector<std::string>{"a.csv"});
  EXPECT_EQ(test::read_text(dir / "a.csv"), "old a\n");
  OutputFiles out;
  out.add(dir / "a.csv", "new a\n");
  out.add(dir / "b.csv", "new b\n");
  EXPECT_EQ(test::read_text(dir / "a.csv"), "old a\n"); // nothing replaced before commit()
  out.commit();
  EXPECT_EQ(names_in(dir.path()), (std::vector<std::string>{"a.csv", "b.csv"}));
  EXPECT_EQ(test::read_text(dir / "a.csv"), "new a\n");
  EXPECT_EQ(test::read_text(dir / "b.csv"), "new b\n");
}

// An interrupt while outputs are being written: the temporary files and directories in
// progress are removed, the old result is untouched and the status is 130. The child process
// (a death test) raises SIGINT itself, so the moment is exact.
TEST(InterruptCleanup, RemovesWhatIsInProgressAndExitsWith130) {
  test::TempDir dir;
  test::write_text(dir / "result.json", "{\"good\": true}\n");
  EXPECT_EXIT(
      {
        install_interrupt_cleanup();
        OutputFiles out;
        out.add(dir / "result.json", "{\"half\": ");
        out.add(dir / "other.csv", "t,f@7:uy\n");
        // A staging directory with files and a subdirectory, as the VTK writer makes.
        const fs::path staging = dir / ".staging";
        const InFlight registration(staging, InFlight::Kind::directory);
        fs::create_directories(staging / "mode_1");
        for (int i = 0; i < 300; ++i) // more than one listing buffer of names
          test::write_text(staging / "mode_1" / ("frame_" + std::to_string(i) + ".vtu"), "x");
        test::write_text(staging / "modes.vtu", "x");
        std::raise(SIGINT);
        std::_Exit(0); // not reached
      },
      ::testing::ExitedWithCode(130), "");
  EXPECT_EQ(names_in(dir.path()), std::vector<std::string>{"result.json"});
  EXPECT_EQ(test::read_text(dir / "result.json"), "{\"good\": true}\n");
}

// An interrupt while outputs are being renamed into place waits for the last rename: the set
// of outputs is never left half old, half new.
TEST(InterruptCleanup, WaitsForACommitToFinish) {
  test::TempDir dir;
  test::write_text(dir / "a.csv", "old a\n");
  test::write_text(dir / "b.csv", "old b\n");
  EXPECT_EXIT(
      {
        install_interrupt_cleanup();
        OutputFiles out;
        out.add(dir / "a.csv", "new a\n");
        out.add(dir / "b.csv", "new b\n");
        const CommitSection section;
        std::raise(SIGTERM); // held back until the section ends
        out.commit();
        test::write_text(dir / "reached.txt", "the handler returned\n");
      },
      ::testing::ExitedWithCode(128 + SIGTERM), "");
  EXPECT_EQ(names_in(dir.path()), (std::vector<std::string>{"a.csv", "b.csv", "reached.txt"}));
  EXPECT_EQ(test::read_text(dir / "a.csv"), "new a\n");
  EXPECT_EQ(test::read_text(dir / "b.csv"), "new b\n");
}

// After protect_inputs(), a file that was read (under any spelling of its path) is never
// written over. In a child process: protection lasts for the rest of the process.
TEST(ProtectInputs, RefusesToWriteOverAFileRead) {
  test::TempDir dir;
  test::write_text(dir / "model.toml", "[model]\n");
  EXPECT_EXIT(
      {
        protect_inputs();
        write_file_atomically(dir / "before.txt", "x"); // not read: fine
        read_file(dir / "model.toml");
        write_file_atomically(dir / "before.txt", "y"); // still fine
        try {
          write_file_atomically(dir.path() / "." / "model.toml", "overwritten");
        } catch (const Error& e) {
          if (std::string(e.what()).find("is an input of this run") != std::string::npos)
            std::_Exit(3);
        }
        std::_Exit(4);
      },
      ::testing::ExitedWithCode(3), "");
  EXPECT_EQ(test::read_text(dir / "model.toml"), "[model]\n");
  EXPECT_EQ(test::read_text(dir / "before.txt"), "y");
}

} // namespace
} // namespace jointid::io
