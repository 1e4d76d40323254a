#pragma once
/// Gmsh mesh files (.msh, ASCII, format 2.2 and 4.1) with 2-node line elements (type 1) and
/// 1-node point elements (type 15). Physical groups of lines become element sets, physical
/// groups of points (or of lines) become node sets. Node and element ids are Gmsh's tags.
#include "fem/model.hpp"

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace jointid::io {

struct GmshMesh {
  struct Line {
    int id = 0;
    int node_a = 0, node_b = 0;
    std::vector<int> groups; ///< physical tags (dimension 1)
    int source_line = 0;     ///< line in the file, for messages
  };
  struct Point {
    int node = 0;
    std::vector<int> groups; ///< physical tags (dimension 0)
  };
  std::filesystem::path path;
  std::vector<fem::Node> nodes;
  std::vector<Line> lines;
  std::vector<Point> points;
  /// Physical names by (dimension, tag).
  std::map<std::pair<int, int>, std::string> names;

  /// Physical tag of a named group of this dimension, or -1.
  int group_tag(int dimension, const std::string& name) const;
  /// Ids of the line elements in a named physical group of lines. Throws io::Error if there
  /// is no such group.
  std::vector<int> elements_in(const std::string& group) const;
  /// Node ids in a named group: the nodes of a point group, or every node of a line group.
  std::vector<int> nodes_in(const std::string& group) const;
};

/// Reads a .msh file; throws io::Error naming the file and line for an unsupported format or
/// element type (e.g. triangles, second-order lines), missing or duplicate nodes, duplicate
/// element ids, and zero-length lines.
GmshMesh read_gmsh(const std::filesystem::path& path);

} // namespace jointid::io
