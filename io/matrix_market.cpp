#include "io/matrix_market.hpp"

#include "fem/text.hpp"
#include "io/files.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <map>
#include <sstream>
#include <string>

namespace jointid::io {

namespace {

std::string lower(std::string s) {
  for (char& c : s)
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string trimmed(const std::string& s) {
  const auto a = s.find_first_not_of(" \t\r");
  if (a == std::string::npos) return "";
  return s.substr(a, s.find_last_not_of(" \t\r") - a + 1);
}

constexpr long long max_size = 10'000'000;

} // namespace

Eigen::SparseMatrix<double> read_matrix_market(const std::filesystem::path& path) {
  const std::string text = read_file(path);
  const std::string name = path.string();
  auto fail = [&](int line, const std::string& what) -> void {
    throw Error(fmt::format("{}:{}: {}", name, line, what));
  };
  std::istringstream in(text);
  std::string line;
  int number = 0;
  if (!std::getline(in, line)) fail(1, "empty file; expected a MatrixMarket header");
  ++number;
  if (line.size() >= 3 && static_cast<unsigned char>(line[0]) == 0xEF &&
      static_cast<unsigned char>(line[1]) == 0xBB && static_cast<unsigned char>(line[2]) == 0xBF)
    line.erase(0, 3); // a UTF-8 byte-order mark
  std::istringstream header(lower(line));
  std::string banner, object, format, field, symmetry;
  header >> banner >> object >> format >> field >> symmetry;
  if (banner != "%%matrixmarket")
    fail(1, "expected the header '%%MatrixMarket matrix coordinate real symmetric' (or "
            "general), got '" +
                trimmed(line) + "'");
  if (object != "matrix") fail(1, "expected a 'matrix' object, got '" + object + "'");
  if (format != "coordinate")
    fail(1, "expected the 'coordinate' (sparse) format, got '" + format +
                "' (dense 'array' files are not read: export K and M as sparse)");
  if (field != "real" && field != "integer" && field != "double")
    fail(1, "expected a 'real' or 'integer' field, got '" + field +
                "' (stiffness and mass matrices are real)");
  if (symmetry != "symmetric" && symmetry != "general")
    fail(1, "expected 'symmetric' or 'general', got '" + symmetry + "'");
  const bool symmetric = symmetry == "symmetric";

  long long rows = -1, cols = -1, entries = -1;
  while (std::getline(in, line)) {
    ++number;
    const std::string t = trimmed(line);
    if (t.empty() || t[0] == '%') continue;
    std::istringstream s(t);
    std::string extra;
    if (!(s >> rows >> cols >> entries) || (s >> extra) || rows <= 0 || cols <= 0 || entries < 0)
      fail(number,
           "expected the size line 'rows columns entries' (positive integers), got '" + t + "'");
    break;
  }
  if (rows < 0) fail(number, "no size line 'rows columns entries' before the end of the file");
  // The largest models jointid is sized for have 10^7 DOFs (docs/scaling.md); the matrix's
  // column index is allocated whole, so a size line alone must not ask for more.
  if (rows > max_size || cols > max_size)
    fail(number, fmt::format("{} x {} is larger than jointid handles (at most {} rows and columns)",
                             rows, cols, max_size));
  if (symmetric && rows != cols)
    fail(number, fmt::format("a symmetric matrix must be square, got {} x {}", rows, cols));

  std::vector<Eigen::Triplet<double>> triplets;
  // Reserved for the entries the file can hold (a line `i j v` takes at least 6 bytes), not for
  // the count the size line announces.
  triplets.reserve(static_cast<std::size_t>(
      std::min<long long>(entries, static_cast<long long>(text.size() / 6 + 1))));
  bool upper = false, lower_side = false;
  int first_upper = 0, first_lower = 0;
  long long read = 0;
  while (read < entries && std::getline(in, line)) {
    ++number;
    const std::string t = trimmed(line);
    if (t.empty() || t[0] == '%') continue;
    std::istringstream s(t);
    long long i = 0, j = 0;
    std::string value_text, extra;
    if (!(s >> i >> j >> value_text) || (s >> extra))
      fail(number, "expected an entry 'row column value', got '" + t + "'");
    double value = 0.0;
    const auto [end, ec] =
        std::from_chars(value_text.data(), value_text.data() + value_text.size(), value);
    if (ec != std::errc() || end != value_text.data() + value_text.size() || !std::isfinite(value))
      fail(number, "expected a finite number as the value, got '" + value_text + "'");
    if (i < 1 || i > rows || j < 1 || j > cols)
      fail(number, fmt::format("entry ({}, {}) is outside the {} x {} matrix (indices are "
                               "1-based)",
                               i, j, rows, cols));
    if (symmetric && i < j && !upper) upper = true, first_upper = number;
    if (symmetric && i > j && !lower_side) lower_side = true, first_lower = number;
    triplets.emplace_back(static_cast<int>(i - 1), static_cast<int>(j - 1), value);
    if (symmetric && i != j)
      triplets.emplace_back(static_cast<int>(j - 1), static_cast<int>(i - 1), value);
    ++read;
  }
  if (read < entries)
    fail(number, fmt::format("the size line announces {} entries, the file has {}", entries, read));
  while (std::getline(in, line)) {
    ++number;
    const std::string t = trimmed(line);
    if (!t.empty() && t[0] != '%')
      fail(number, fmt::format("more entries than the {} the size line announces", entries));
  }
  if (upper && lower_side)
    fail(std::max(first_upper, first_lower),
         fmt::format("a symmetric file holds one triangle, this one has entries above (line {}) "
                     "and below (line {}) the diagonal",
                     first_upper, first_lower));
  Eigen::SparseMatrix<double> A(static_cast<Eigen::Index>(rows), static_cast<Eigen::Index>(cols));
  A.setFromTriplets(triplets.begin(), triplets.end()); // repeated entries are added
  return A;
}

void write_matrix_market(const std::filesystem::path& path, const Eigen::SparseMatrix<double>& A) {
  if (A.rows() != A.cols())
    throw Error(
        fmt::format("{}: matrix is {} x {}, not square", path.string(), A.rows(), A.cols()));
  const Eigen::SparseMatrix<double> At = A.transpose();
  double largest = 0.0;
  for (Eigen::Index c = 0; c < A.outerSize(); ++c)
    for (Eigen::SparseMatrix<double>::InnerIterator it(A, c); it; ++it)
      largest = std::max(largest, std::abs(it.value()));
  const Eigen::SparseMatrix<double> D = A - At;
  for (Eigen::Index c = 0; c < D.outerSize(); ++c)
    for (Eigen::SparseMatrix<double>::InnerIterator it(D, c); it; ++it)
      if (std::abs(it.value()) > 1e-12 * largest)
        throw Error(fmt::format("{}: the matrix is not symmetric: entries ({}, {}) differ by {}",
                                path.string(), it.row() + 1, it.col() + 1, it.value()));
  std::string out = "%%MatrixMarket matrix coordinate real symmetric\n% written by jointid\n";
  std::string body;
  long long count = 0;
  for (Eigen::Index c = 0; c < A.outerSize(); ++c)
    for (Eigen::SparseMatrix<double>::InnerIterator it(A, c); it; ++it)
      if (it.row() >= it.col()) {
        body += fmt::format("{} {} {}\n", it.row() + 1, it.col() + 1, shortest(it.value()));
        ++count;
      }
  out += fmt::format("{} {} {}\n", A.rows(), A.cols(), count) + body;
  write_file_atomically(path, out);
}

std::vector<fem::NodeDof> read_dof_table(const std::filesystem::path& path) {
  const std::string text = read_file(path);
  std::istringstream in(text);
  std::string line;
  int number = 0;
  std::vector<fem::NodeDof> out;
  std::map<std::pair<int, int>, int> seen;
  while (std::getline(in, line)) {
    ++number;
    if (number == 1 && line.size() >= 3 && static_cast<unsigned char>(line[0]) == 0xEF &&
        static_cast<unsigned char>(line[1]) == 0xBB && static_cast<unsigned char>(line[2]) == 0xBF)
      line.erase(0, 3);
    const auto hash = line.find('#');
    const std::string t = trimmed(hash == std::string::npos ? line : line.substr(0, hash));
    if (t.empty()) continue;
    fem::NodeDof nd;
    try {
      nd = fem::parse_node_dof(t);
    } catch (const std::invalid_argument&) {
      throw Error(fmt::format("{}:{}: expected NODE:DOF with a node id and one of ux, uy, uz, rx, "
                              "ry, rz (e.g. 7:uy), got '{}'",
                              path.string(), number, t));
    }
    if (nd.node <= 0)
      throw Error(fmt::format("{}:{}: node ids must be > 0, got '{}'", path.string(), number, t));
    const auto [it, fresh] = seen.emplace(std::pair(nd.node, static_cast<int>(nd.dof)), number);
    if (!fresh)
      throw Error(
          fmt::format("{}:{}: {} is already on line {}", path.string(), number, t, it->second));
    out.push_back(nd);
  }
  if (out.empty()) throw Error(path.string() + ": no DOFs (expected one NODE:DOF per line)");
  return out;
}

} // namespace jointid::io
