#pragma once
/// A small MatrixMarket writer for the benchmarks: a symmetric sparse matrix as
/// `coordinate real symmetric`, lower triangle only, 1-based indices, values written with the
/// shortest text that reads back to the same double.
#include <Eigen/SparseCore>

#include <charconv>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#include <system_error>

namespace jointid::bench {

inline void write_matrix_market_symmetric(const std::string& path,
                                          const Eigen::SparseMatrix<double>& A) {
  if (A.rows() != A.cols())
    throw std::invalid_argument("write_matrix_market_symmetric: " + path + ": matrix is " +
                                std::to_string(A.rows()) + " x " + std::to_string(A.cols()) +
                                ", not square");
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(path.c_str(), "wb"),
                                                       &std::fclose);
  if (!file)
    throw std::runtime_error("cannot open " + path + " for writing (does the folder exist?)");
  long long lower = 0;
  for (Eigen::Index c = 0; c < A.outerSize(); ++c)
    for (Eigen::SparseMatrix<double>::InnerIterator it(A, c); it; ++it)
      if (it.row() >= it.col()) ++lower;
  std::fprintf(file.get(), "%%%%MatrixMarket matrix coordinate real symmetric\n");
  std::fprintf(file.get(), "%% written by jointid bench (lower triangle)\n");
  std::fprintf(file.get(), "%lld %lld %lld\n", static_cast<long long>(A.rows()),
               static_cast<long long>(A.cols()), lower);

  // Column-major storage: column by column gives the MatrixMarket entries sorted by column.
  std::string buffer;
  buffer.reserve(1 << 20);
  char text[64];
  auto append = [&](auto value) {
    const auto [end, ec] = std::to_chars(text, text + sizeof text, value);
    if (ec != std::errc()) throw std::runtime_error("write_matrix_market_symmetric: to_chars");
    buffer.append(text, end);
  };
  for (Eigen::Index c = 0; c < A.outerSize(); ++c) {
    for (Eigen::SparseMatrix<double>::InnerIterator it(A, c); it; ++it) {
      if (it.row() < it.col()) continue;
      append(static_cast<long long>(it.row() + 1));
      buffer.push_back(' ');
      append(static_cast<long long>(it.col() + 1));
      buffer.push_back(' ');
      append(it.value());
      buffer.push_back('\n');
    }
    if (buffer.size() > (1u << 20) - 4096 || c + 1 == A.outerSize()) {
      if (std::fwrite(buffer.data(), 1, buffer.size(), file.get()) != buffer.size())
        throw std::runtime_error("write error on " + path + " (disk full?)");
      buffer.clear();
    }
  }
  if (std::fclose(file.release()) != 0) throw std::runtime_error("write error on " + path);
}

} // namespace jointid::bench
