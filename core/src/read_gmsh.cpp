// Gmsh MSH 2.2 and 4.1 ASCII reader. Nodes keep file order and may have any
// positive, non-contiguous tags. 4-node tets are read; 10-, 20-, 35- and
// 56-node tets keep their 4 corners (Gmsh lists the corners first). Other volume elements are
// an error (simulating the tets alone would drop part of the body); point,
// line and surface elements are boundary markup, skipped and counted. Tets
// are resolved against the node tags once the whole file is read, so
// section order does not matter.
#include <algorithm>
#include <limits>
#include <map>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "edgefem/core/error.hpp"
#include "edgefem/core/read_mesh.hpp"
#include "text_reader.hpp"

namespace edgefem {

namespace {

// Nodes of an element type read as a tet (Gmsh lists a tet's 4 corners
// first at every order: 4, 11 quadratic, 29 cubic, 30 quartic, 31 quintic),
// or 0.
int tet_node_count(std::int64_t type) {
    switch (type) {
        case 4: return 4;
        case 11: return 10;
        case 29: return 20;
        case 30: return 35;
        case 31: return 56;
        default: return 0;
    }
}

// Dimension of an element type (Gmsh's GmshDefines.h), -1 when unknown.
int element_dimension(std::int64_t type) {
    static const std::map<std::int64_t, int> dims = {
        {15, 0}, {1, 1},  {8, 1},  {26, 1}, {27, 1}, {28, 1}, {2, 2},  {3, 2},  {9, 2},
        {10, 2}, {16, 2}, {20, 2}, {21, 2}, {22, 2}, {23, 2}, {24, 2}, {25, 2}, {4, 3},
        {5, 3},  {6, 3},  {7, 3},  {11, 3}, {12, 3}, {13, 3}, {14, 3}, {17, 3}, {18, 3},
        {19, 3}, {29, 3}, {30, 3}, {31, 3}, {32, 3}, {33, 3},
    };
    const auto it = dims.find(type);
    return it == dims.end() ? -1 : it->second;
}

std::string element_type_name(std::int64_t type) {
    static const std::map<std::int64_t, const char*> names = {
        {1, "line"},
        {2, "triangle"},
        {3, "quadrangle"},
        {4, "tetrahedron"},
        {5, "hexahedron"},
        {6, "prism"},
        {7, "pyramid"},
        {8, "3-node line"},
        {9, "6-node triangle"},
        {10, "9-node quadrangle"},
        {11, "10-node tetrahedron"},
        {12, "27-node hexahedron"},
        {13, "18-node prism"},
        {14, "14-node pyramid"},
        {15, "point"},
        {16, "8-node quadrangle"},
        {17, "20-node hexahedron"},
        {18, "15-node prism"},
        {19, "13-node pyramid"},
        {29, "20-node tetrahedron"},
        {30, "35-node tetrahedron"},
        {31, "56-node tetrahedron"},
    };
    const auto it = names.find(type);
    return it == names.end() ? "element" : it->second;
}

struct GmshData {
    int version = 0;  // 2 or 41
    bool have_nodes = false, have_elements = false;
    Mesh mesh;
    std::vector<std::int64_t> node_tag_line;  // line of each node's tag (4.1: the tag line)
    std::vector<std::int64_t> tet_nodes;      // 4 node tags per tet
    std::vector<int> tet_entity_dim;          // 4.1: dimension of the tet's entity
    std::vector<std::int64_t> tet_entity;     // 4.1: entity tag of the tet's block
    std::unordered_map<std::int64_t, std::int64_t> volume_physical;  // 4.1 $Entities
    std::unordered_map<std::int64_t, std::int64_t> surface_physical; // 4.1 $Entities
    std::vector<std::int64_t> tri_nodes;      // 3 node tags per kept triangle
    std::vector<std::int64_t> tri_tag;        // 2.2: its physical tag; 4.1: its surface entity
    std::vector<std::int64_t> tri_line;
    std::map<int, std::string> surface_names;  // $PhysicalNames of dimension 2
    std::map<std::int64_t, std::int64_t> skipped;                      // type -> count
    std::map<std::int64_t, std::int64_t> volume_skipped;               // type -> count: an error
    std::int64_t first_volume_line = 0;                                // of the first volume element skipped
    std::vector<std::pair<std::int64_t, std::size_t>> mid_nodes;       // higher-order tets: (tag, tet)
    std::map<int, std::int64_t> high_order;                            // nodes per tet -> tets
};

std::int64_t single_int(detail::TextReader& r, const std::string& what) {
    r.require_line(what);
    auto tk = r.tokens();
    const std::int64_t v = r.next_int(tk, what);
    r.expect_end(tk, what);
    return v;
}

void expect_line(detail::TextReader& r, const std::string& expected, const std::string& context) {
    r.require_line("'" + expected + "'");
    if (r.line() != expected)
        r.fail("expected '" + expected + "' " + context + ", got '" +
               detail::quote(r.line()) + "'");
}

int region_from_tag(const detail::TextReader& r, std::int64_t tag) {
    if (tag < std::numeric_limits<int>::min() || tag > std::numeric_limits<int>::max())
        r.fail("physical tag " + std::to_string(tag) + " does not fit an int region id");
    return static_cast<int>(tag);
}

void add_node(detail::TextReader& r, GmshData& d, std::int64_t tag, std::int64_t tag_line,
              detail::LineTokens& tk, int extra_allowed) {
    auto& m = d.mesh;
    const index_t v = m.num_vertices();
    if (tag < 1) r.fail_at(tag_line, "node tag " + std::to_string(tag) + " must be positive", v);
    double p[3];
    p[0] = r.next_double(tk, "x coordinate");
    p[1] = r.next_double(tk, "y coordinate");
    p[2] = r.next_double(tk, "z coordinate");
    for (int k = 0; k < extra_allowed && !tk.empty(); ++k) r.next_double(tk, "parametric coordinate");
    r.expect_end(tk, "the coordinates of node " + std::to_string(tag));
    detail::check_finite(r, p, v, tag);
    m.X.insert(m.X.end(), p, p + 3);
    m.source.vertex_line.push_back(r.line_no());
    m.source.vertex_id.push_back(tag);
    d.node_tag_line.push_back(tag_line);
}

// Reads the nodes of a tet of any order; the nodes past the corners
// are only checked to exist (the corners come first).
void add_tet(detail::TextReader& r, GmshData& d, std::int64_t tag, detail::LineTokens& tk,
             int nodes, int region, int entity_dim, std::int64_t entity) {
    const std::size_t t = d.mesh.source.tet_id.size();
    for (int k = 0; k < 4; ++k) d.tet_nodes.push_back(r.next_int(tk, "tet node tag"));
    for (int k = 4; k < nodes; ++k) d.mid_nodes.emplace_back(r.next_int(tk, "tet node tag"), t);
    if (nodes > 4) ++d.high_order[nodes];
    r.expect_end(tk, "the " + std::to_string(nodes) + " nodes of tetrahedron " + std::to_string(tag));
    d.mesh.region.push_back(region);
    d.mesh.source.tet_line.push_back(r.line_no());
    d.mesh.source.tet_id.push_back(tag);
    d.tet_entity_dim.push_back(entity_dim);
    d.tet_entity.push_back(entity);
}

// Nodes of a triangle type kept as a tagged triangle (3, or 6 for the
// quadratic triangle, corners first), or 0.
int triangle_node_count(std::int64_t type) { return type == 2 ? 3 : type == 9 ? 6 : 0; }

// Reads a triangle's nodes (the corners kept) to the end of its line.
void add_triangle(detail::TextReader& r, GmshData& d, std::int64_t tag, detail::LineTokens& tk, int nodes,
                  std::int64_t surface_tag) {
    for (int k = 0; k < nodes; ++k) {
        const std::int64_t node = r.next_int(tk, "triangle node tag");
        if (k < 3) d.tri_nodes.push_back(node);
    }
    r.expect_end(tk, "the " + std::to_string(nodes) + " nodes of triangle " + std::to_string(tag));
    d.tri_tag.push_back(surface_tag);
    d.tri_line.push_back(r.line_no());
}

// $PhysicalNames: 'dim tag "name"' lines; the surfaces' (dim 2) are kept.
void read_physical_names(detail::TextReader& r, GmshData& d) {
    const index_t n = r.check_count(single_int(r, "the physical name count"), 3, "physical name");
    for (index_t i = 0; i < n; ++i) {
        r.require_line("physical name " + std::to_string(i + 1) + " of " + std::to_string(n));
        auto tk = r.tokens();
        const std::int64_t dim = r.next_int(tk, "physical dimension");
        const std::int64_t tag = r.next_int(tk, "physical tag");
        const std::string_view line = r.line();
        const std::size_t open = line.find('"'), close = line.rfind('"');
        if (open == std::string_view::npos || close == open)
            r.fail("expected 'dim tag \"name\"', got '" + detail::quote(line) + "'");
        for (std::size_t k = close + 1; k < line.size(); ++k)
            if (line[k] != ' ' && line[k] != '\t' && line[k] != '\r')
                r.fail("unexpected '" + detail::quote(line.substr(k)) + "' after the physical name");
        if (dim == 2) d.surface_names[region_from_tag(r, tag)] = std::string(line.substr(open + 1, close - open - 1));
    }
    expect_line(r, "$EndPhysicalNames", "after " + std::to_string(n) + " physical names");
}

// Counts `count` skipped elements of `type`; volume elements are kept apart,
// as they make the mesh unusable.
void skip_elements(GmshData& d, std::int64_t type, int dim, std::int64_t count, std::int64_t line) {
    const bool volume = dim == 3 || element_dimension(type) == 3;
    if (volume && d.volume_skipped.empty()) d.first_volume_line = line;
    (volume ? d.volume_skipped : d.skipped)[type] += count;
}

// "2 x triangle (type 2), 1 x line (type 1)".
std::string summary(const std::map<std::int64_t, std::int64_t>& counts) {
    std::string out;
    for (const auto& [type, count] : counts)
        out += (out.empty() ? "" : ", ") + std::to_string(count) + " x " + element_type_name(type) +
               " (type " + std::to_string(type) + ")";
    return out;
}

void read_nodes_22(detail::TextReader& r, GmshData& d) {
    const index_t n = r.check_count(single_int(r, "the node count"), 4, "node");
    for (index_t i = 0; i < n; ++i) {
        r.require_line("node " + std::to_string(i + 1) + " of " + std::to_string(n));
        auto tk = r.tokens();
        const std::int64_t tag = r.next_int(tk, "node tag");
        add_node(r, d, tag, r.line_no(), tk, 0);
    }
    expect_line(r, "$EndNodes", "after " + std::to_string(n) + " nodes");
}

void read_elements_22(detail::TextReader& r, GmshData& d) {
    const index_t n = r.check_count(single_int(r, "the element count"), 3, "element");
    for (index_t i = 0; i < n; ++i) {
        r.require_line("element " + std::to_string(i + 1) + " of " + std::to_string(n));
        auto tk = r.tokens();
        const std::int64_t tag = r.next_int(tk, "element tag");
        const std::int64_t type = r.next_int(tk, "element type");
        const std::int64_t ntags = r.next_int(tk, "number of tags");
        if (ntags < 0 || static_cast<std::size_t>(ntags) > tk.count())
            r.fail("bad number of tags " + std::to_string(ntags) + " for element " +
                   std::to_string(tag));
        const int nodes = tet_node_count(type);
        const int tri_nodes = triangle_node_count(type);
        if (nodes == 0) {
            // MSH 2.2 does not say an element's dimension; only the type does.
            if (element_dimension(type) < 0)
                r.fail("element type " + std::to_string(type) +
                       " is unknown: cannot tell whether it is a volume element");
            skip_elements(d, type, element_dimension(type), 1, r.line_no());
            if (tri_nodes == 0) continue;
        }
        std::int64_t physical = 0;
        for (std::int64_t k = 0; k < ntags; ++k) {
            const std::int64_t value = r.next_int(tk, "element tag value");
            if (k == 0) physical = value;
        }
        if (tri_nodes)
            add_triangle(r, d, tag, tk, tri_nodes, region_from_tag(r, physical));
        else
            add_tet(r, d, tag, tk, nodes, region_from_tag(r, physical), 0, 0);
    }
    expect_line(r, "$EndElements", "after " + std::to_string(n) + " elements");
}

void read_entities_41(detail::TextReader& r, GmshData& d) {
    r.require_line("the entity counts");
    auto header = r.tokens();
    std::int64_t counts[4];
    for (auto& c : counts) c = r.next_int(header, "entity count");
    r.expect_end(header, "the 4 entity counts");
    for (auto& c : counts) c = r.check_count(c, 4, "entity");
    for (std::int64_t i = 0; i < counts[0] + counts[1]; ++i)
        r.require_line("a point or curve entity");
    // Surface and volume entities: 'tag box(6) nphys phys ...'; the first
    // physical tag, if any, is kept.
    const auto entities = [&](std::int64_t count, const std::string& kind,
                              std::unordered_map<std::int64_t, std::int64_t>& physical) {
        for (std::int64_t i = 0; i < count; ++i) {
            r.require_line(kind + " entity " + std::to_string(i + 1));
            auto tk = r.tokens();
            const std::int64_t tag = r.next_int(tk, kind + " tag");
            for (int k = 0; k < 6; ++k) r.next_double(tk, "bounding box coordinate");
            const std::int64_t nphys = r.next_int(tk, "number of physical tags");
            if (nphys < 0 || static_cast<std::size_t>(nphys) > tk.count())
                r.fail("bad number of physical tags " + std::to_string(nphys));
            if (nphys > 0) physical[tag] = r.next_int(tk, "physical tag");
        }
    };
    entities(counts[2], "surface", d.surface_physical);
    entities(counts[3], "volume", d.volume_physical);
    expect_line(r, "$EndEntities", "after the entities");
}

void read_nodes_41(detail::TextReader& r, GmshData& d) {
    r.require_line("the node block header");
    auto header = r.tokens();
    const std::int64_t nblocks = r.next_int(header, "number of node blocks");
    const std::int64_t nnodes = r.next_int(header, "number of nodes");
    r.next_int(header, "minimum node tag");
    r.next_int(header, "maximum node tag");
    r.expect_end(header, "the node block header");
    const index_t nb = r.check_count(nblocks, 4, "node block");
    const index_t n = r.check_count(nnodes, 4, "node");
    std::int64_t total = 0;
    std::vector<std::pair<std::int64_t, std::int64_t>> tags;  // (tag, line) of one block
    for (index_t b = 0; b < nb; ++b) {
        r.require_line("node block " + std::to_string(b + 1) + " of " + std::to_string(nb));
        auto tk = r.tokens();
        r.next_int(tk, "entity dimension");
        r.next_int(tk, "entity tag");
        const std::int64_t parametric = r.next_int(tk, "parametric flag");
        const std::int64_t count = r.next_int(tk, "number of nodes in the block");
        r.expect_end(tk, "the node block header");
        const index_t m = r.check_count(count, 4, "node");
        total += m;
        if (total > n)
            r.fail("the node blocks hold more nodes than the header's count " +
                   std::to_string(n));
        tags.clear();
        for (index_t i = 0; i < m; ++i) {
            const std::int64_t tag = single_int(r, "node tag");
            tags.emplace_back(tag, r.line_no());
        }
        for (index_t i = 0; i < m; ++i) {
            r.require_line("the coordinates of node " + std::to_string(tags[i].first));
            auto xyz = r.tokens();
            add_node(r, d, tags[i].first, tags[i].second, xyz, parametric ? 3 : 0);
        }
    }
    if (total != n)
        r.fail("the node blocks hold " + std::to_string(total) + " nodes, the header says " +
               std::to_string(n));
    expect_line(r, "$EndNodes", "after " + std::to_string(n) + " nodes");
}

void read_elements_41(detail::TextReader& r, GmshData& d) {
    r.require_line("the element block header");
    auto header = r.tokens();
    const std::int64_t nblocks = r.next_int(header, "number of element blocks");
    const std::int64_t nelems = r.next_int(header, "number of elements");
    r.next_int(header, "minimum element tag");
    r.next_int(header, "maximum element tag");
    r.expect_end(header, "the element block header");
    const index_t nb = r.check_count(nblocks, 4, "element block");
    const index_t n = r.check_count(nelems, 2, "element");
    std::int64_t total = 0;
    for (index_t b = 0; b < nb; ++b) {
        r.require_line("element block " + std::to_string(b + 1) + " of " + std::to_string(nb));
        auto tk = r.tokens();
        const std::int64_t dim = r.next_int(tk, "entity dimension");
        const std::int64_t entity = r.next_int(tk, "entity tag");
        const std::int64_t type = r.next_int(tk, "element type");
        const std::int64_t count = r.next_int(tk, "number of elements in the block");
        r.expect_end(tk, "the element block header");
        const index_t m = r.check_count(count, 2, "element");
        total += m;
        if (total > n)
            r.fail("the element blocks hold more elements than the header's count " +
                   std::to_string(n));
        const int nodes = tet_node_count(type);
        const int tri_nodes = dim == 2 ? triangle_node_count(type) : 0;
        for (index_t i = 0; i < m; ++i) {
            r.require_line("element " + std::to_string(i + 1) + " of block " +
                           std::to_string(b + 1));
            if (nodes == 0) {
                if (i == 0) skip_elements(d, type, static_cast<int>(dim), m, r.line_no());
                if (tri_nodes == 0) continue;
            }
            auto et = r.tokens();
            const std::int64_t tag = r.next_int(et, "element tag");
            if (tri_nodes)
                add_triangle(r, d, tag, et, tri_nodes, entity);
            else
                add_tet(r, d, tag, et, nodes, 0, static_cast<int>(dim), entity);
        }
    }
    if (total != n)
        r.fail("the element blocks hold " + std::to_string(total) + " elements, the header says " +
               std::to_string(n));
    expect_line(r, "$EndElements", "after " + std::to_string(n) + " elements");
}

void skip_section(detail::TextReader& r, const std::string& name) {
    const std::string end = "$End" + name;
    const std::int64_t start = r.line_no();
    while (r.next_line())
        if (r.line() == end) return;
    r.fail_at(start, "section $" + name + " has no " + end + " (file truncated?)");
}

// Maps node tags to vertex indices: a dense table when the tags are compact
// (the usual case), else a sorted list searched by bisection.
class TagMap {
public:
    TagMap(const detail::TextReader& r, const GmshData& d) {
        const auto& ids = d.mesh.source.vertex_id;
        sorted_.reserve(ids.size());
        for (std::size_t i = 0; i < ids.size(); ++i)
            sorted_.emplace_back(ids[i], static_cast<index_t>(i));
        std::sort(sorted_.begin(), sorted_.end());
        for (std::size_t i = 1; i < sorted_.size(); ++i)
            if (sorted_[i].first == sorted_[i - 1].first) {
                const index_t a = std::min(sorted_[i].second, sorted_[i - 1].second);
                const index_t b = std::max(sorted_[i].second, sorted_[i - 1].second);
                r.fail_at(d.node_tag_line[b],
                          "duplicate node tag " + std::to_string(sorted_[i].first) +
                              " (first defined at line " + std::to_string(d.node_tag_line[a]) +
                              ")",
                          b);
            }
        if (!sorted_.empty() &&
            sorted_.back().first - sorted_.front().first < 4 * static_cast<std::int64_t>(ids.size()) + 1024) {
            min_ = sorted_.front().first;
            dense_.assign(static_cast<std::size_t>(sorted_.back().first - min_ + 1), -1);
            for (const auto& [tag, v] : sorted_) dense_[tag - min_] = v;
        }
    }
    index_t find(std::int64_t tag) const {
        if (!dense_.empty())
            return (tag >= min_ && tag - min_ < static_cast<std::int64_t>(dense_.size()))
                       ? dense_[tag - min_]
                       : -1;
        const auto it = std::lower_bound(sorted_.begin(), sorted_.end(),
                                         std::make_pair(tag, index_t{-1}));
        return (it != sorted_.end() && it->first == tag) ? it->second : -1;
    }

private:
    std::vector<std::pair<std::int64_t, index_t>> sorted_;
    std::vector<index_t> dense_;
    std::int64_t min_ = 0;
};

}  // namespace

Mesh read_gmsh(const std::string& path, ReadReport* report) {
    detail::TextReader r(path, '\0');
    GmshData d;
    r.require_line("'$MeshFormat'");
    if (r.line() != "$MeshFormat")
        r.fail("not a Gmsh MSH file: expected '$MeshFormat', got '" + detail::quote(r.line()) + "'");
    r.require_line("the MSH version line");
    {
        auto tk = r.tokens();
        const std::string_view version = r.need(tk, "MSH version");
        const std::string_view file_type = r.need(tk, "MSH file type");
        if (file_type == "1") r.fail("binary MSH is not supported; save the mesh as ASCII");
        if (file_type != "0")
            r.fail("bad MSH file type '" + detail::quote(file_type) + "' (0 = ASCII)");
        if (version == "2" || version == "2.0" || version == "2.1" || version == "2.2")
            d.version = 2;
        else if (version == "4.1")
            d.version = 41;
        else
            r.fail("unsupported MSH version '" + detail::quote(version) +
                   "' (supported: 2.2 and 4.1 ASCII)");
    }
    expect_line(r, "$EndMeshFormat", "after the version line");

    while (r.next_line()) {
        const std::string_view line = r.line();
        if (line.front() != '$')
            r.fail("expected a section such as $Nodes, got '" + detail::quote(line) + "'");
        const std::string name(line.substr(1));
        if (name == "Nodes" || name == "Elements") {
            bool& seen = name == "Nodes" ? d.have_nodes : d.have_elements;
            if (seen) r.fail("a second $" + name + " section is not supported");
            seen = true;
            if (name == "Nodes")
                d.version == 2 ? read_nodes_22(r, d) : read_nodes_41(r, d);
            else
                d.version == 2 ? read_elements_22(r, d) : read_elements_41(r, d);
        } else if (name == "Entities" && d.version == 41) {
            read_entities_41(r, d);
        } else if (name == "PhysicalNames") {
            read_physical_names(r, d);
        } else if (name.rfind("End", 0) == 0 || name == "MeshFormat" || name.empty()) {
            r.fail("unexpected '" + detail::quote(line) + "'");
        } else {
            skip_section(r, name);
        }
    }
    if (!d.have_nodes) r.fail("no $Nodes section");
    if (!d.have_elements) r.fail("no $Elements section");
    if (!d.volume_skipped.empty())
        r.fail_at(d.first_volume_line, "mesh has " + summary(d.volume_skipped) +
                                           ": edgefem simulates tets only; convert the mesh to tets");

    Mesh& mesh = d.mesh;
    auto& src = mesh.source;
    src.vertex_file = src.tet_file = path;
    if (d.version == 41)
        for (std::size_t t = 0; t < mesh.region.size(); ++t) {
            const auto it = d.volume_physical.find(d.tet_entity[t]);
            const std::int64_t tag = (d.tet_entity_dim[t] == 3 && it != d.volume_physical.end())
                                         ? it->second
                                         : d.tet_entity[t];
            if (tag < std::numeric_limits<int>::min() || tag > std::numeric_limits<int>::max())
                r.fail_at(src.tet_line[t], "region tag " + std::to_string(tag) + " does not fit an int");
            mesh.region[t] = static_cast<int>(tag);
        }

    const TagMap map(r, d);
    mesh.tets.resize(d.tet_nodes.size());
    for (std::size_t i = 0; i < d.tet_nodes.size(); ++i) {
        const index_t v = map.find(d.tet_nodes[i]);
        if (v < 0) {
            const std::size_t t = i / 4;
            r.fail_at(src.tet_line[t],
                      detail::item_label("tet", static_cast<std::int64_t>(t), src.tet_id[t]) +
                          ": node tag " + std::to_string(d.tet_nodes[i]) +
                          " is not defined in $Nodes",
                      static_cast<std::int64_t>(t));
        }
        mesh.tets[i] = v;
    }

    // Tagged triangles: 4.1 gives their surface entity, whose physical tag
    // (if any) is the tag.
    for (std::size_t k = 0; k < d.tri_tag.size(); ++k) {
        std::int64_t tag = d.tri_tag[k];
        if (d.version == 41)
            if (const auto it = d.surface_physical.find(tag); it != d.surface_physical.end()) tag = it->second;
        if (tag < std::numeric_limits<int>::min() || tag > std::numeric_limits<int>::max())
            r.fail_at(d.tri_line[k], "surface tag " + std::to_string(tag) + " does not fit an int");
        mesh.surfaces.tag.push_back(static_cast<int>(tag));
    }
    mesh.surfaces.vertices.resize(d.tri_nodes.size());
    for (std::size_t i = 0; i < d.tri_nodes.size(); ++i) {
        const index_t v = map.find(d.tri_nodes[i]);
        if (v < 0)
            r.fail_at(d.tri_line[i / 3], "triangle " + std::to_string(i / 3) + ": node tag " +
                                             std::to_string(d.tri_nodes[i]) + " is not defined in $Nodes");
        mesh.surfaces.vertices[i] = v;
    }
    mesh.surfaces.names = std::move(d.surface_names);
    if (!d.tri_tag.empty()) {
        src.triangle_file = path;
        src.triangle_line = std::move(d.tri_line);
    }

    for (const auto& [tag, t] : d.mid_nodes)
        if (map.find(tag) < 0)
            r.fail_at(src.tet_line[t],
                      detail::item_label("tet", static_cast<std::int64_t>(t), src.tet_id[t]) +
                          ": node tag " + std::to_string(tag) + " is not defined in $Nodes",
                      static_cast<std::int64_t>(t));

    if (report) {
        for (const auto& [type, count] : d.skipped) report->skipped_elements += count;
        if (!report->skipped_summary.empty() && !d.skipped.empty()) report->skipped_summary += ", ";
        report->skipped_summary += summary(d.skipped);
        std::string kinds;
        for (const auto& [nodes, count] : d.high_order)
            kinds += (kinds.empty() ? "" : ", ") + std::to_string(count) + " x " + std::to_string(nodes) + "-node";
        report->high_order_tets = report->high_order_tets || !d.high_order.empty();
        if (!d.high_order.empty())
            report->warnings.push_back(
                path + ": higher-order tets (" + kinds + "): kept the 4 corner nodes; the other nodes are left "
                       "unreferenced (validate_mesh with compact_unreferenced removes them)");
    }
    return std::move(d.mesh);
}

}  // namespace edgefem
