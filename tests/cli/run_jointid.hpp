#pragma once
// Runs the built `jointid` program as a user would (stdout and stderr captured), for the CLI
// tests.
#include "io/test_files.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <sys/wait.h>
#include <vector>

namespace jointid::test {

struct Outcome {
  int status = -1;
  std::string out, err;
};

inline std::string quoted(const std::string& s) {
  std::string q = "'";
  for (char c : s)
    q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// Runs jointid with `args`, capturing stdout and stderr through files in `dir`; `launcher`
// (e.g. mpirun and its options, already quoted) goes in front.
inline Outcome jointid(const std::vector<std::string>& args, const std::filesystem::path& dir,
                       const std::string& launcher = "") {
  std::string command = launcher + quoted(JOINTID_EXE);
  for (const auto& a : args)
    command.append(" ").append(quoted(a));
  const std::filesystem::path out = dir / "stdout.txt", err = dir / "stderr.txt";
  command.append(" > ").append(quoted(out.string())).append(" 2> ").append(quoted(err.string()));
  const int raw = std::system(command.c_str());
  Outcome run;
  run.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  run.out = read_text(out);
  run.err = read_text(err);
  std::filesystem::remove(out);
  std::filesystem::remove(err);
  return run;
}

// A failed run: non-zero status and exactly one line "jointid: ..." on stderr.
inline void expect_one_line_error(const Outcome& run, const std::string& part = "") {
  EXPECT_NE(run.status, 0);
  EXPECT_EQ(run.err.rfind("jointid: ", 0), 0u) << run.err;
  EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
  if (!part.empty()) {
    EXPECT_NE(run.err.find(part), std::string::npos) << "'" << part << "' not in: " << run.err;
  }
}

} // namespace jointid::test
