#pragma once
/// Shared by the fuzz targets: the readers take a file path, so each input is written to a file
/// of this process (in /dev/shm when there is one: no disk traffic) and read back from there.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

namespace jointid::fuzz {

/// A directory of this process for the inputs (removed at exit).
inline const std::filesystem::path& input_directory() {
  struct Directory {
    std::filesystem::path path;
    Directory() {
      const std::filesystem::path base = std::filesystem::exists("/dev/shm")
                                             ? std::filesystem::path("/dev/shm")
                                             : std::filesystem::temp_directory_path();
      path = base / ("jointid_fuzz." + std::to_string(::getpid()));
      std::filesystem::create_directories(path);
    }
    ~Directory() {
      std::error_code ignored;
      std::filesystem::remove_all(path, ignored);
    }
  };
  static const Directory directory;
  return directory.path;
}

/// The file `name` in input_directory(), holding `size` bytes of `data`.
inline std::filesystem::path input_file(const std::string& name, const std::uint8_t* data,
                                        std::size_t size) {
  const auto path = input_directory() / name;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  out.close();
  if (!out) {
    std::fprintf(stderr, "cannot write the fuzz input %s\n", path.c_str());
    std::abort();
  }
  return path;
}

} // namespace jointid::fuzz
