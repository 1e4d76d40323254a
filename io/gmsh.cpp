#include "io/gmsh.hpp"

#include "io/files.hpp"

#include <algorithm>
#include <set>
#include <sstream>

namespace jointid::io {

namespace {

constexpr int line2 = 1, point1 = 15;

// Number of nodes of the Gmsh element types we may meet, to skip or name them.
int nodes_of(int type) {
  switch (type) {
  case 1:
    return 2; // 2-node line
  case 2:
    return 3; // triangle
  case 3:
    return 4; // quadrangle
  case 4:
    return 4; // tetrahedron
  case 5:
    return 8; // hexahedron
  case 6:
    return 6; // prism
  case 7:
    return 5; // pyramid
  case 8:
    return 3; // 3-node line
  case 9:
    return 6; // 6-node triangle
  case 15:
    return 1; // point
  default:
    return -1;
  }
}

std::string type_name(int type) {
  switch (type) {
  case 2:
    return "triangle";
  case 3:
    return "quadrangle";
  case 4:
    return "tetrahedron";
  case 5:
    return "hexahedron";
  case 8:
    return "3-node (second-order) line";
  case 9:
    return "6-node triangle";
  default:
    return "element type " + std::to_string(type);
  }
}

// Line-oriented tokenizer that knows where it is in the file.
class Reader {
public:
  Reader(const std::filesystem::path& path) : path_(path), text_(read_file(path)), in_(text_) {}

  [[noreturn]] void fail(const std::string& what) const {
    throw Error(path_.string() + ":" + std::to_string(line_no_) + ": " + what);
  }
  bool next_line(std::string& line) {
    if (!std::getline(in_, line)) return false;
    ++line_no_;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    return true;
  }
  std::istringstream line(const char* expecting) {
    std::string l;
    if (!next_line(l)) fail(std::string("unexpected end of file, expected ") + expecting);
    return std::istringstream(l);
  }
  template <class... T> void read(const char* expecting, T&... values) {
    std::istringstream s = line(expecting);
    if (!(s >> ... >> values)) fail(std::string("expected ") + expecting);
  }
  void expect(const std::string& tag) {
    std::string l;
    if (!next_line(l)) fail("unexpected end of file, expected " + tag);
    if (l != tag) fail("expected " + tag + ", got '" + l + "'");
  }
  void skip_section(const std::string& name) {
    std::string l;
    while (next_line(l))
      if (l == "$End" + name) return;
    fail("section $" + name + " has no $End" + name);
  }
  int line_no() const { return line_no_; }
  const std::filesystem::path& path() const { return path_; }

private:
  std::filesystem::path path_;
  std::string text_;
  std::istringstream in_;
  int line_no_ = 0;
};

void add_node(GmshMesh& mesh, std::set<int>& ids, Reader& r, int id, double x, double y, double z) {
  if (!ids.insert(id).second) r.fail("duplicate node " + std::to_string(id));
  mesh.nodes.push_back({id, Eigen::Vector3d(x, y, z)});
}

void add_element(GmshMesh& mesh, std::set<int>& ids, Reader& r, int id, int type,
                 const std::vector<int>& nodes, const std::vector<int>& groups) {
  if (type != line2 && type != point1)
    r.fail("unsupported element " + std::to_string(id) + " (" + type_name(type) +
           "): jointid reads 2-node lines (type 1) and points (type 15); mesh the curves with "
           "first-order "
           "elements only (Mesh.ElementOrder = 1) and leave surfaces unmeshed");
  if (type == point1) {
    mesh.points.push_back({nodes[0], groups});
    return;
  }
  if (!ids.insert(id).second) r.fail("duplicate element " + std::to_string(id));
  mesh.lines.push_back({id, nodes[0], nodes[1], groups, r.line_no()});
}

void read_physical_names(GmshMesh& mesh, Reader& r) {
  int n = 0;
  r.read("the number of physical names", n);
  for (int i = 0; i < n; ++i) {
    std::istringstream s = r.line("a physical name: dim tag \"name\"");
    int dim = 0, tag = 0;
    std::string rest;
    if (!(s >> dim >> tag) || !std::getline(s >> std::ws, rest))
      r.fail("expected a physical name: dim tag \"name\"");
    if (rest.size() >= 2 && rest.front() == '"' && rest.back() == '"')
      rest = rest.substr(1, rest.size() - 2);
    mesh.names[{dim, tag}] = rest;
  }
  r.expect("$EndPhysicalNames");
}

void read_v2(GmshMesh& mesh, Reader& r) {
  std::string l;
  std::set<int> node_ids, element_ids;
  while (r.next_line(l)) {
    if (l == "$PhysicalNames") {
      read_physical_names(mesh, r);
    } else if (l == "$Nodes") {
      int n = 0;
      r.read("the number of nodes", n);
      for (int i = 0; i < n; ++i) {
        int id = 0;
        double x = 0, y = 0, z = 0;
        r.read("a node: id x y z", id, x, y, z);
        add_node(mesh, node_ids, r, id, x, y, z);
      }
      r.expect("$EndNodes");
    } else if (l == "$Elements") {
      int n = 0;
      r.read("the number of elements", n);
      for (int i = 0; i < n; ++i) {
        std::istringstream s = r.line("an element: id type ntags tags... nodes...");
        int id = 0, type = 0, ntags = 0;
        if (!(s >> id >> type >> ntags) || ntags < 0)
          r.fail("expected an element: id type ntags tags... nodes...");
        // Read one by one (not sized from ntags first): a line holds only so many tags.
        std::vector<int> tags;
        for (int t = 0, k = 0; k < ntags; ++k) {
          if (!(s >> t))
            r.fail("element " + std::to_string(id) + ": expected " + std::to_string(ntags) +
                   " tags");
          tags.push_back(t);
        }
        const int nn = nodes_of(type);
        if (nn < 0)
          r.fail("unknown element type " + std::to_string(type) + " for element " +
                 std::to_string(id));
        std::vector<int> nodes(nn);
        for (int& v : nodes)
          if (!(s >> v))
            r.fail("element " + std::to_string(id) + ": expected " + std::to_string(nn) +
                   " node ids");
        // Format 2.2: the first tag is the physical group (0: none), the second the entity.
        std::vector<int> groups;
        if (ntags >= 1 && tags[0] != 0) groups.push_back(tags[0]);
        add_element(mesh, element_ids, r, id, type, nodes, groups);
      }
      r.expect("$EndElements");
    } else if (!l.empty() && l[0] == '$' && l.rfind("$End", 0) != 0) {
      r.skip_section(l.substr(1));
    }
  }
}

void read_v4(GmshMesh& mesh, Reader& r) {
  std::string l;
  std::set<int> node_ids, element_ids;
  std::map<std::pair<int, int>, std::vector<int>>
      entity_groups; // (dim, entity tag) → physical tags
  while (r.next_line(l)) {
    if (l == "$PhysicalNames") {
      read_physical_names(mesh, r);
    } else if (l == "$Entities") {
      std::size_t counts[4];
      r.read("the entity counts", counts[0], counts[1], counts[2], counts[3]);
      for (int dim = 0; dim < 4; ++dim)
        for (std::size_t i = 0; i < counts[dim]; ++i) {
          std::istringstream s = r.line("an entity");
          int tag = 0;
          double box[6];
          const int nbox = dim == 0 ? 3 : 6;
          s >> tag;
          for (int k = 0; k < nbox; ++k)
            s >> box[k];
          long long nphys = 0; // signed: "-3" must not wrap to a huge count
          if (!(s >> nphys))
            r.fail("expected an entity: tag, coordinates, number of physical tags");
          if (nphys < 0)
            r.fail("entity " + std::to_string(tag) +
                   ": expected a number of physical tags >= 0, got " + std::to_string(nphys));
          std::vector<int> phys;
          for (long long k = 0; k < nphys; ++k) {
            int p = 0;
            if (!(s >> p))
              r.fail("entity " + std::to_string(tag) + ": expected " + std::to_string(nphys) +
                     " physical tags");
            phys.push_back(p);
          }
          entity_groups[{dim, tag}] = phys;
        }
      r.expect("$EndEntities");
    } else if (l == "$Nodes") {
      std::size_t blocks = 0, total = 0, min_tag = 0, max_tag = 0;
      r.read("numEntityBlocks numNodes minNodeTag maxNodeTag", blocks, total, min_tag, max_tag);
      for (std::size_t b = 0; b < blocks; ++b) {
        int dim = 0, tag = 0, parametric = 0;
        std::size_t count = 0;
        r.read("entityDim entityTag parametric numNodesInBlock", dim, tag, parametric, count);
        std::vector<int> ids; // one a line: not sized from `count` before the lines are there
        for (std::size_t k = 0; k < count; ++k) {
          int id = 0;
          r.read("a node tag", id);
          ids.push_back(id);
        }
        for (int id : ids) {
          std::istringstream s = r.line("node coordinates x y z");
          double x = 0, y = 0, z = 0;
          if (!(s >> x >> y >> z)) r.fail("expected node coordinates x y z");
          add_node(mesh, node_ids, r, id, x, y, z);
        }
      }
      r.expect("$EndNodes");
    } else if (l == "$Elements") {
      std::size_t blocks = 0, total = 0, min_tag = 0, max_tag = 0;
      r.read("numEntityBlocks numElements minElementTag maxElementTag", blocks, total, min_tag,
             max_tag);
      for (std::size_t b = 0; b < blocks; ++b) {
        int dim = 0, tag = 0, type = 0;
        std::size_t count = 0;
        r.read("entityDim entityTag elementType numElementsInBlock", dim, tag, type, count);
        const int nn = nodes_of(type);
        if (nn < 0) r.fail("unknown element type " + std::to_string(type));
        const auto it = entity_groups.find({dim, tag});
        const std::vector<int> groups = it != entity_groups.end() ? it->second : std::vector<int>{};
        for (std::size_t e = 0; e < count; ++e) {
          std::istringstream s = r.line("an element: tag nodes...");
          int id = 0;
          std::vector<int> nodes(nn);
          if (!(s >> id)) r.fail("expected an element tag");
          for (int& v : nodes)
            if (!(s >> v))
              r.fail("element " + std::to_string(id) + ": expected " + std::to_string(nn) +
                     " node ids");
          add_element(mesh, element_ids, r, id, type, nodes, groups);
        }
      }
      r.expect("$EndElements");
    } else if (!l.empty() && l[0] == '$' && l.rfind("$End", 0) != 0) {
      r.skip_section(l.substr(1));
    }
  }
}

} // namespace

int GmshMesh::group_tag(int dimension, const std::string& name) const {
  for (const auto& [key, n] : names)
    if (key.first == dimension && n == name) return key.second;
  return -1;
}

std::vector<int> GmshMesh::elements_in(const std::string& group) const {
  const int tag = group_tag(1, group);
  if (tag < 0) throw Error(path.string() + ": no physical group of lines named '" + group + "'");
  std::vector<int> ids;
  for (const auto& l : lines)
    if (std::find(l.groups.begin(), l.groups.end(), tag) != l.groups.end()) ids.push_back(l.id);
  return ids;
}

std::vector<int> GmshMesh::nodes_in(const std::string& group) const {
  std::set<int> ids;
  const int point_tag = group_tag(0, group), line_tag = group_tag(1, group);
  if (point_tag < 0 && line_tag < 0)
    throw Error(path.string() + ": no physical group of points or lines named '" + group + "'");
  for (const auto& p : points)
    if (point_tag >= 0 && std::find(p.groups.begin(), p.groups.end(), point_tag) != p.groups.end())
      ids.insert(p.node);
  for (const auto& l : lines)
    if (line_tag >= 0 && std::find(l.groups.begin(), l.groups.end(), line_tag) != l.groups.end())
      ids.insert(l.node_a), ids.insert(l.node_b);
  return {ids.begin(), ids.end()};
}

GmshMesh read_gmsh(const std::filesystem::path& path) {
  Reader r(path);
  GmshMesh mesh;
  mesh.path = path;
  r.expect("$MeshFormat");
  std::string version;
  int file_type = 0, data_size = 0;
  r.read("version file-type data-size", version, file_type, data_size);
  const bool v2 = version == "2.2" || version == "2.0" || version == "2.1", v4 = version == "4.1";
  if (!v2 && !v4) r.fail("unsupported .msh format " + version + " (expected 2.2 or 4.1)");
  if (file_type != 0)
    r.fail("binary .msh files are not supported; save as ASCII (Mesh.Binary = 0)");
  r.expect("$EndMeshFormat");
  if (v2)
    read_v2(mesh, r);
  else
    read_v4(mesh, r);

  // References and geometry, with the line of the offending element.
  std::map<int, Eigen::Vector3d> at;
  for (const auto& n : mesh.nodes)
    at[n.id] = n.x;
  for (const auto& l : mesh.lines) {
    const std::string where =
        path.string() + ":" + std::to_string(l.source_line) + ": element " + std::to_string(l.id);
    for (int v : {l.node_a, l.node_b})
      if (!at.count(v))
        throw Error(where + " refers to node " + std::to_string(v) + ", which is not in $Nodes");
    if ((at[l.node_a] - at[l.node_b]).norm() == 0.0)
      throw Error(where + " has zero length (nodes " + std::to_string(l.node_a) + " and " +
                  std::to_string(l.node_b) + " coincide)");
  }
  for (const auto& p : mesh.points)
    if (!at.count(p.node))
      throw Error(path.string() + ": point element refers to node " + std::to_string(p.node) +
                  ", which is not in $Nodes");
  if (mesh.lines.empty()) throw Error(path.string() + ": the mesh has no 2-node line elements");
  return mesh;
}

} // namespace jointid::io
