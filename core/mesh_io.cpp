// Mesh loading: OBJ through tinyobjloader, PLY through the small parser
// below, either one optionally gzip-compressed. Both formats are first read
// into a RawMesh (polygons exactly as stored), which one shared function then
// validates, triangulates and cleans, so every format reports problems alike.
#include "core/mesh.h"

#include "core/error.h"
#include "core/geometry.h"
#include "core/limits.h"
#include "core/messages.h"
#include "core/simd/width1.h"

#include <tiny_obj_loader.h>
#include <zlib.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <initializer_list>
#include <iterator>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <stdexcept>
#include <string_view>
#include <unordered_set>
#include <vector>

namespace pathlab {
namespace {

namespace fs = std::filesystem;

// Throws "<file>: <problem>", or "<file>:<line>: <problem>" given a line number.
[[noreturn]] void fail(const fs::path& file, const std::string& problem, int line = 0) {
  throw InputError(file.string() + (line > 0 ? ":" + std::to_string(line) : "") + ": " + problem);
}

enum class Number { kOk, kMalformed, kOverflow };

// Parses all of `token` as a decimal number into `out` (a leading '+' is
// allowed; hex is not). An overflow such as 1e999 sets `out` to +-infinity
// and returns kOverflow; an underflow such as 1e-999 is a valid (tiny or zero) number.
Number parse_number(std::string_view token, double& out) {
  if (token.size() > 1 && token[0] == '+' && token[1] != '-') token.remove_prefix(1);  // from_chars rejects '+'
  const char* const last = token.data() + token.size();
  const auto [end, ec] = std::from_chars(token.data(), last, out);
  if (end != last || (ec != std::errc() && ec != std::errc::result_out_of_range)) return Number::kMalformed;
  if (ec == std::errc()) return Number::kOk;
  // from_chars leaves `out` alone when out of range; strtod tells over- from underflow.
  out = std::strtod(std::string(token).c_str(), nullptr);
  return std::isinf(out) ? Number::kOverflow : Number::kOk;
}

// Polygons as stored in the file, before validation and triangulation.
struct RawMesh {
  std::vector<vec3> positions;
  std::vector<std::int64_t> indices;       // every face's vertex indices, concatenated
  std::vector<std::size_t> face_start{0};  // face f is indices[face_start[f], face_start[f + 1])
  int number_base = 0;  // messages number faces and vertices as the format does: PLY 0, OBJ 1
  // Vertex attributes. PLY stores them per vertex (indexed like positions,
  // the index arrays below empty); OBJ per corner, with indices of their own
  // parallel to `indices` (-1: this corner has none).
  std::vector<vec3> normals;
  std::vector<vec2> uvs;
  std::vector<std::int64_t> normal_indices, uv_indices;
  // Per face, or empty: OBJ `usemtl` slots (TriangleMesh::face_material),
  // and OBJ smoothing groups when they are to make the normals.
  std::vector<std::uint16_t> face_material;
  std::vector<std::string> material_names;
  std::vector<std::uint32_t> smoothing_groups;
  std::vector<std::string> ignored;

  std::size_t face_count() const { return face_start.size() - 1; }
  bool per_corner() const { return !normal_indices.empty() || !uv_indices.empty(); }
};

// The vertex attributes must be finite, and normals not of zero length;
// normals come back unit length.
void check_attributes(const fs::path& file, RawMesh& raw) {
  const auto name = [&](std::size_t i) { return std::to_string(i + static_cast<std::size_t>(raw.number_base)); };
  const bool obj = raw.number_base == 1;
  for (std::size_t i = 0; i < raw.normals.size(); ++i) {
    vec3& n = raw.normals[i];
    const double length = glm::length(dvec3(n));
    if (!is_finite(n) || !(length > 1e-30)) {
      // PLY: "vertex 7's normal"; OBJ: "normal 7 (vn)".
      std::ostringstream problem;
      problem << (obj ? "normal " + name(i) + " (vn)" : "vertex " + name(i) + "'s normal")
              << (is_finite(n) ? " has zero length (" : " is not finite (") << n.x << ", " << n.y << ", " << n.z << ")";
      fail(file, problem.str());
    }
    n = vec3(dvec3(n) / length);
  }
  for (std::size_t i = 0; i < raw.uvs.size(); ++i) {
    const vec2& t = raw.uvs[i];
    if (!std::isfinite(t.x) || !std::isfinite(t.y)) {
      std::ostringstream problem;
      problem << (obj ? "texture coordinate " + name(i) + " (vt)" : "vertex " + name(i) + "'s texture coordinate")
              << " is not finite (" << t.x << ", " << t.y << ")";
      fail(file, problem.str());
    }
  }
  const auto check_refs = [&](const std::vector<std::int64_t>& refs, std::size_t count, const char* what) {
    for (std::size_t f = 0; f < raw.face_count(); ++f)
      for (std::size_t k = raw.face_start[f]; k < raw.face_start[f + 1]; ++k)
        if (refs[k] >= static_cast<std::int64_t>(count) || refs[k] < -1)
          fail(file, "face " + name(f) + " refers to " + what + " " + std::to_string(refs[k] + raw.number_base) +
                         " but the mesh has " + std::to_string(count));
  };
  if (!raw.normal_indices.empty()) check_refs(raw.normal_indices, raw.normals.size(), "normal");
  if (!raw.uv_indices.empty()) check_refs(raw.uv_indices, raw.uvs.size(), "texture coordinate");
}

void check_indices(const fs::path& file, const RawMesh& raw) {
  const auto vertex_count = static_cast<std::int64_t>(raw.positions.size());
  for (std::size_t f = 0; f < raw.face_count(); ++f) {
    for (std::size_t k = raw.face_start[f]; k < raw.face_start[f + 1]; ++k) {
      const std::int64_t i = raw.indices[k];
      if (i < 0 || i >= vertex_count)
        fail(file, "face " + std::to_string(f + raw.number_base) + " refers to vertex " +
                       std::to_string(i + raw.number_base) + " but the mesh has " +
                       std::to_string(vertex_count) + " vertices");
    }
  }
}

// One triangle's angle-weighted contributions to its corners' normals
// (Thürmer & Wüthrich 1998): the unit face normal times each corner's angle.
// All zero for a triangle of zero area.
std::array<dvec3, 3> angle_weighted(const vec3& a, const vec3& b, const vec3& c) {
  const dvec3 p[3] = {dvec3(a), dvec3(b), dvec3(c)};
  const dvec3 face = glm::cross(p[1] - p[0], p[2] - p[0]);
  const double length = glm::length(face);
  std::array<dvec3, 3> out{dvec3(0.0), dvec3(0.0), dvec3(0.0)};
  if (!(length > 0.0)) return out;
  for (int k = 0; k < 3; ++k) out[k] = corner_angle(p[k], p[(k + 1) % 3], p[(k + 2) % 3]) * (face / length);
  return out;
}

// Validates `raw` (normalising its normals), fan-triangulates its polygons and
// drops degenerate triangles.
TriangleMesh finish(const fs::path& file, RawMesh raw, MeshLoadReport* report) {
  for (std::size_t v = 0; v < raw.positions.size(); ++v) {
    const vec3& p = raw.positions[v];
    if (!is_finite(p)) {
      std::ostringstream problem;
      problem << "vertex " << v + raw.number_base << " has a non-finite coordinate (" << p.x
              << ", " << p.y << ", " << p.z << ")";
      fail(file, problem.str());
    }
  }
  if (raw.face_count() == 0) fail(file, "no faces");
  if (raw.positions.size() > std::numeric_limits<std::uint32_t>::max())
    fail(file, "too many vertices (" + std::to_string(raw.positions.size()) + ")");
  check_indices(file, raw);
  check_attributes(file, raw);

  // PLY's attributes are per vertex: the mesh takes raw's arrays as they
  // are (at the end). OBJ corners: one vertex per distinct (position,
  // normal, texture coordinate); a corner without a normal in a mesh with
  // normals takes its face's, keyed by the normal's bits. With smoothing
  // groups, a corner of group g > 0 is keyed by (position, g, texture
  // coordinate) and its normal computed at the end; a corner of group 0
  // takes its face's normal, like a corner without one.
  TriangleMesh mesh;
  const bool smoothing = !raw.smoothing_groups.empty();
  const bool per_corner = raw.per_corner() || smoothing;
  std::map<std::array<std::int64_t, 6>, std::uint32_t> welded;
  const bool has_normals = !raw.normals.empty(), has_uvs = !raw.uvs.empty();
  // Smoothing only: each vertex's (position, group), and each triangle's group.
  std::vector<std::pair<std::int64_t, std::uint32_t>> vertex_group;
  std::vector<std::uint32_t> triangle_group;
  // The unit normal of face f, from its first three corners. Adding 0 turns
  // a -0 component into +0: the key is the bits, and equal normals must weld.
  const auto face_normal = [&](std::size_t f) {
    const std::size_t s = raw.face_start[f];
    const dvec3 a(raw.positions[raw.indices[s]]), b(raw.positions[raw.indices[s + 1]]),
        c(raw.positions[raw.indices[s + 2]]);
    const dvec3 cr = glm::cross(b - a, c - a);
    const double len = glm::length(cr);
    return len > 0.0 ? vec3(cr / len) + vec3(0.0f) : vec3(0.0f, 0.0f, 1.0f);
  };
  const auto corner = [&](std::size_t k, std::size_t f) -> std::uint32_t {
    if (!per_corner) return static_cast<std::uint32_t>(raw.indices[k]);
    const std::int64_t ni = has_normals ? raw.normal_indices[k] : -1;
    const std::int64_t ti = has_uvs ? raw.uv_indices[k] : -1;
    const std::uint32_t group = smoothing ? raw.smoothing_groups[f] : 0;
    // Group g > 0 stands where a normal index would (-1 - g: no index is).
    const vec3 n = ni >= 0 ? raw.normals[static_cast<std::size_t>(ni)]
                   : has_normals || smoothing ? face_normal(f) : vec3(0.0f);
    const std::array<std::int64_t, 6> key =
        group > 0 ? std::array<std::int64_t, 6>{raw.indices[k], -1 - static_cast<std::int64_t>(group), 0, 0, 0, ti}
                  : std::array<std::int64_t, 6>{raw.indices[k], ni, std::bit_cast<std::int32_t>(n.x),
                                                std::bit_cast<std::int32_t>(n.y), std::bit_cast<std::int32_t>(n.z), ti};
    const auto [it, added] = welded.try_emplace(key, static_cast<std::uint32_t>(mesh.positions.size()));
    if (added) {
      mesh.positions.push_back(raw.positions[static_cast<std::size_t>(raw.indices[k])]);
      if (has_normals || smoothing) mesh.normals.push_back(n);  // a group's: replaced at the end
      if (has_uvs) mesh.uvs.push_back(ti >= 0 ? raw.uvs[static_cast<std::size_t>(ti)] : vec2(0.0f));
      if (smoothing) vertex_group.emplace_back(raw.indices[k], group);
    }
    return it->second;
  };
  std::size_t dropped = 0;
  for (std::size_t f = 0; f < raw.face_count(); ++f) {
    // A fan around the polygon's first vertex: correct for convex polygons
    // (all that OBJ/PLY writers normally emit); concave ones may fold over.
    const std::size_t first = raw.face_start[f];
    for (std::size_t k = first + 1; k + 1 < raw.face_start[f + 1]; ++k) {
      const glm::u64vec3 pos(raw.indices[first], raw.indices[k], raw.indices[k + 1]);
      const dvec3 a(raw.positions[pos.x]), b(raw.positions[pos.y]), c(raw.positions[pos.z]);
      const bool repeated = pos.x == pos.y || pos.y == pos.z || pos.x == pos.z;
      if (repeated || glm::length(glm::cross(b - a, c - a)) == 0.0) {
        ++dropped;
        continue;
      }
      // One corner after the other: the order numbers the welded vertices.
      const std::uint32_t c0 = corner(first, f);
      const std::uint32_t c1 = corner(k, f);
      const std::uint32_t c2 = corner(k + 1, f);
      mesh.triangles.emplace_back(c0, c1, c2);
      if (!raw.face_material.empty()) mesh.face_material.push_back(raw.face_material[f]);
      if (smoothing) triangle_group.push_back(raw.smoothing_groups[f]);
    }
  }
  if (mesh.triangles.empty())
    fail(file, "no usable triangles (" + std::to_string(dropped) + " degenerate dropped)");
  if (smoothing) {
    // A group's normal at a position sums over all of the group's triangles
    // there, whatever their texture coordinates (a UV seam is no crease).
    std::map<std::pair<std::int64_t, std::uint32_t>, dvec3> sums;
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
      if (triangle_group[t] == 0) continue;
      const glm::uvec3& tri = mesh.triangles[t];
      const std::array<dvec3, 3> w = angle_weighted(mesh.positions[tri.x], mesh.positions[tri.y], mesh.positions[tri.z]);
      for (int k = 0; k < 3; ++k) sums[vertex_group[tri[k]]] += w[k];
    }
    for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
      if (vertex_group[v].second == 0) continue;
      const dvec3 sum = sums[vertex_group[v]];
      const double length = glm::length(sum);
      if (length > 0.0) mesh.normals[v] = vec3(sum / length);  // else its first face's normal stays
    }
  }
  if (!per_corner) {
    mesh.positions = std::move(raw.positions);
    mesh.normals = std::move(raw.normals);
    mesh.uvs = std::move(raw.uvs);
  }
  mesh.material_names = std::move(raw.material_names);
  if (report) {
    report->faces_in_file = raw.face_count();
    report->triangles_loaded = mesh.triangles.size();
    report->degenerate_dropped = dropped;
    report->ignored = std::move(raw.ignored);
  }
  return mesh;
}

// ---------------------------------------------------------------- OBJ

// What scan_obj finds besides broken vertices.
struct ObjDirectives {
  std::vector<std::string> materials;  // `usemtl` names, in the order of first use
  std::vector<std::string> libraries;  // what `mtllib` lines name
  // Per kind (vertex, normal, texture coordinate): the largest positive
  // index a face gives, with its token and line.
  struct Furthest {
    long long index = 0;
    std::string token;
    int line = 0;
  };
  Furthest furthest[3];
};

// The kinds of OBJ index, in the order of scan_obj's counts ("v", "vn", "vt").
constexpr const char* kObjIndexNames[3] = {"vertex", "normal", "texture coordinate"};

// " (valid: 1..N or -N..-1)", or " (none is defined)".
std::string obj_index_range(long long count) {
  if (count == 0) return " (none is defined)";
  return " (valid: 1.." + std::to_string(count) + " or -" + std::to_string(count) + "..-1)";
}

// tinyobj reads a face index it cannot parse ("a") as 0 and reports "zero
// value", and resolves a negative index before checking it, so its messages
// name neither the token nor the index as written. Check each token of an
// "f" line here: v, v/vt, v//vn or v/vt/vn, each index a non-zero integer;
// a negative one counts back from the `defined` (v, vn, vt) before this line.
void check_obj_face(const fs::path& file, std::string_view line, int line_no, const int (&defined)[3],
                    ObjDirectives::Furthest (&furthest)[3]) {
  constexpr int kKindOfSlot[3] = {0, 2, 1};  // v/vt/vn -> vertex, texture coordinate, normal
  std::size_t i = 1;
  while (true) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    if (i >= line.size()) return;
    const std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
    const std::string_view token = line.substr(start, i - start);
    if (token.starts_with("#")) return;  // a comment to the end of the line
    std::size_t from = 0;
    for (int slot = 0; slot < 3 && from <= token.size(); ++slot) {
      const std::size_t slash = std::min(token.find('/', from), token.size());
      const std::string_view part = token.substr(from, slash - from);
      from = slash + 1;
      const int kind = kKindOfSlot[slot];
      if (part.empty()) {
        if (slot == 0) fail(file, "face token " + quote_input(token) + ": the vertex index is missing", line_no);
        continue;
      }
      long long index = 0;
      const auto [end, ec] = std::from_chars(part.data() + (part[0] == '+' ? 1 : 0), part.data() + part.size(), index);
      if (ec != std::errc() || end != part.data() + part.size() || index == 0)
        fail(file, "face token " + quote_input(token) + ": " + kObjIndexNames[kind] + " index " + quote_input(part) +
                       " is not a non-zero integer" + obj_index_range(defined[kind]),
             line_no);
      if (index < 0 && -index > defined[kind])
        fail(file, "face token " + quote_input(token) + ": " + kObjIndexNames[kind] + " index " +
                       std::to_string(index) + " counts back past the " + std::to_string(defined[kind]) + " " +
                       kObjIndexNames[kind] + "(s) given before this line" + obj_index_range(defined[kind]),
             line_no);
      if (index > furthest[kind].index) furthest[kind] = {index, std::string(token), line_no};
    }
  }
}

// tinyobj turns a coordinate it cannot parse ("nan", "inf", "1,5", "abc")
// into 0 without a warning, so a broken vertex would load silently at the
// origin. Check the coordinates of every vertex, normal and texture
// coordinate line ("v", "vn", "vt" as tinyobj recognises them) before handing
// the text over. The same pass collects the `usemtl` names, read as tinyobj
// reads them, and the `mtllib` lines.
ObjDirectives scan_obj(const fs::path& file, std::string_view text) {
  ObjDirectives found;
  const auto is_blank = [](char c) { return c == ' ' || c == '\t'; };
  struct Kind {
    std::string_view tag, name;
    int needed, checked;  // coordinates required, and how many are read
    int count = 0;
  };
  Kind kinds[] = {{"v", "vertex", 3, 3}, {"vn", "normal", 3, 3}, {"vt", "texture coordinate", 1, 2}};
  std::unordered_set<std::string_view> seen_materials;  // views into `text`, which outlives the scan
  for (int line_no = 1; !text.empty(); ++line_no) {
    // Lines end like tinyobj's: at "\n", "\r\n" or a lone "\r".
    const std::size_t eol = std::min(text.find_first_of("\r\n"), text.size());
    std::string_view line = text.substr(0, eol);
    text.remove_prefix(std::min(eol + (text.substr(eol).starts_with("\r\n") ? 2 : 1), text.size()));
    line.remove_prefix(std::min(line.find_first_not_of(" \t"), line.size()));
    // tinyobj takes any line that starts with "usemtl" (no blank needed), and
    // the name up to the next blank, "\r" or NUL; an empty name is no material.
    if (line.starts_with("usemtl")) {
      std::string_view name = line.substr(6);
      name.remove_prefix(std::min(name.find_first_not_of(" \t"), name.size()));
      name = name.substr(0, std::min(name.find_first_of(std::string_view(" \t\r\0", 4)), name.size()));
      if (!name.empty() && seen_materials.emplace(name).second) {
        found.materials.emplace_back(name);
        if (found.materials.size() >= TriangleMesh::kNoFileMaterial)
          fail(file, "too many materials (more than " + std::to_string(TriangleMesh::kNoFileMaterial - 1) +
                         " 'usemtl' names)", line_no);
      }
      continue;
    }
    if (line.size() > 6 && line.starts_with("mtllib") && is_blank(line[6])) {
      std::string_view names = line.substr(7);
      names.remove_prefix(std::min(names.find_first_not_of(" \t"), names.size()));
      names = names.substr(0, names.find_last_not_of(" \t") + 1);
      if (!names.empty()) found.libraries.emplace_back(names);
      continue;
    }
    if (line.size() > 1 && line[0] == 'f' && is_blank(line[1])) {
      check_obj_face(file, line, line_no, {kinds[0].count, kinds[1].count, kinds[2].count}, found.furthest);
      continue;
    }
    Kind* kind = nullptr;
    for (Kind& k : kinds)
      if (line.size() > k.tag.size() && line.starts_with(k.tag) && is_blank(line[k.tag.size()])) kind = &k;
    if (kind == nullptr) continue;
    ++kind->count;
    const auto bad = [&](const std::string& problem) {
      fail(file, std::string(kind->name) + " " + std::to_string(kind->count) + problem, line_no);
    };
    std::string_view coords[3];
    int n = 0;
    for (std::size_t i = kind->tag.size(); n < kind->checked;) {
      while (i < line.size() && is_blank(line[i])) ++i;
      if (i == line.size()) break;
      const std::size_t start = i;
      while (i < line.size() && !is_blank(line[i])) ++i;
      coords[n++] = line.substr(start, i - start);
    }
    if (n < kind->needed)
      bad(" has " + std::to_string(n) + " coordinates (" + std::to_string(kind->needed) + " needed)");
    const auto cut = [](std::string_view c) { return std::string(c.substr(0, 40)); };
    for (int c = 0; c < n; ++c) {
      double value = 0.0;
      if (parse_number(coords[c], value) == Number::kMalformed) bad(": malformed number '" + cut(coords[c]) + "'");
      if (!std::isfinite(value)) {
        std::string all;
        for (int k = 0; k < n; ++k) all += (k ? ", " : "") + cut(coords[k]);
        bad(" has a non-finite coordinate (" + all + ")");
      }
    }
  }
  // Positive indices may refer to vertices given later in the file: checked
  // against the totals at the end, the furthest of each kind.
  const int totals[3] = {kinds[0].count, kinds[1].count, kinds[2].count};
  for (int k = 0; k < 3; ++k) {
    const ObjDirectives::Furthest& f = found.furthest[k];
    if (f.index > totals[k])
      fail(file, "face token " + quote_input(f.token) + ": " + kObjIndexNames[k] + " index " + std::to_string(f.index) +
                     " is beyond the " + std::to_string(totals[k]) + " " + kObjIndexNames[k] + "(s) of the file" +
                     obj_index_range(totals[k]),
           f.line);
  }
  return found;
}

// tinyobj numbers a face's material (material_ids) only by the names an
// `mtllib` line brought in. This reader brings in the names the scan found,
// as materials without content, whatever library is named: pathlab takes
// nothing else from a .mtl file (the scene gives the materials).
class UsemtlNames : public tinyobj::MaterialReader {
 public:
  explicit UsemtlNames(const std::vector<std::string>& names) : names_(names) {}
  bool operator()(const std::string& /*library*/, std::vector<tinyobj::material_t>* materials,
                  std::map<std::string, int>* ids, std::string* /*warning*/, std::string* /*error*/) override {
    if (!materials->empty()) return true;  // a second `mtllib` line
    for (const std::string& name : names_) {
      ids->emplace(name, static_cast<int>(materials->size()));
      tinyobj::material_t m;
      m.name = name;
      materials->push_back(std::move(m));
    }
    return true;
  }

 private:
  const std::vector<std::string>& names_;
};

// The line numbers in a tinyobj message ("line 7.", "line: 7") less one:
// for text that a line was put in front of.
std::string renumber_lines(const std::string& message) {
  std::string out;
  std::size_t at = 0;
  for (std::size_t found; (found = message.find("line", at)) != std::string::npos;) {
    std::size_t digits = found + 4;
    while (digits < message.size() && (message[digits] == ' ' || message[digits] == ':')) ++digits;
    std::size_t end = digits;
    while (end < message.size() && std::isdigit(static_cast<unsigned char>(message[end]))) ++end;
    out += message.substr(at, digits - at);
    if (end > digits) out += std::to_string(std::stoll(message.substr(digits, end - digits)) - 1);
    at = end;
  }
  return out + message.substr(at);
}

RawMesh parse_obj(const fs::path& file, std::string_view text, const MeshLoadOptions& options) {
  const ObjDirectives directives = scan_obj(file, text);
  // The names reach tinyobj only through an `mtllib` line (UsemtlNames),
  // which a file need not have before its first `usemtl`: put one in front.
  const bool named = !directives.materials.empty();
  std::istringstream in((named ? "mtllib pathlab-usemtl-names\n" : "") + std::string(text));
  UsemtlNames names(directives.materials);
  tinyobj::attrib_t attrib;
  std::vector<tinyobj::shape_t> shapes;
  std::vector<tinyobj::material_t> materials;
  std::string warning, error;
  if (!tinyobj::LoadObj(&attrib, &shapes, &materials, &warning, &error, &in, &names, /*triangulate=*/true,
                        /*default_vcols_fallback=*/false)) {
    if (named) error = renumber_lines(error);
    while (!error.empty() && std::isspace(static_cast<unsigned char>(error.back()))) error.pop_back();
    fail(file, "cannot parse OBJ: " + error);
  }

  RawMesh raw;
  raw.number_base = 1;
  const std::vector<tinyobj::real_t>& v = attrib.vertices;
  for (std::size_t i = 0; i + 2 < v.size(); i += 3) raw.positions.emplace_back(v[i], v[i + 1], v[i + 2]);
  for (std::size_t i = 0; i + 2 < attrib.normals.size(); i += 3)
    raw.normals.emplace_back(attrib.normals[i], attrib.normals[i + 1], attrib.normals[i + 2]);
  for (std::size_t i = 0; i + 1 < attrib.texcoords.size(); i += 2)
    raw.uvs.emplace_back(attrib.texcoords[i], attrib.texcoords[i + 1]);
  // Smoothing groups make normals only where the file gives none.
  bool smoothing = false;
  if (raw.normals.empty() && options.smoothing_groups)
    for (const tinyobj::shape_t& shape : shapes)
      for (const unsigned id : shape.mesh.smoothing_group_ids) smoothing |= id != 0;
  if (named) raw.material_names = directives.materials;
  // All shapes index the same vertex arrays, so concatenating them is trivial.
  for (const tinyobj::shape_t& shape : shapes) {
    std::size_t k = 0;
    for (std::size_t f = 0; f < shape.mesh.num_face_vertices.size(); ++f) {
      for (unsigned j = 0; j < shape.mesh.num_face_vertices[f]; ++j, ++k) {
        const tinyobj::index_t& index = shape.mesh.indices[k];
        raw.indices.push_back(index.vertex_index);
        if (!raw.normals.empty()) raw.normal_indices.push_back(index.normal_index);
        if (!raw.uvs.empty()) raw.uv_indices.push_back(index.texcoord_index);
      }
      raw.face_start.push_back(raw.indices.size());
      // tinyobj's material -1: before the first `usemtl` (or an empty name).
      const int id = shape.mesh.material_ids[f];
      if (named) raw.face_material.push_back(id < 0 ? TriangleMesh::kNoFileMaterial : static_cast<std::uint16_t>(id));
      if (smoothing) raw.smoothing_groups.push_back(shape.mesh.smoothing_group_ids[f]);
    }
  }
  // The library's content is the one thing of the materials not used.
  bool uses_materials = false;
  for (const std::uint16_t m : raw.face_material) uses_materials |= m != TriangleMesh::kNoFileMaterial;
  if (uses_materials && !directives.libraries.empty()) {
    std::string list;
    for (const std::string& l : directives.libraries) list += (list.empty() ? "" : ", ") + l;
    raw.ignored.push_back("the material library's content (" + list +
                          ": Kd, Ks, maps; the scene's materials give the colours)");
  }

  // tinyobj does not fail on these; it warns and silently drops the face.
  if (warning.find("Degenerated face") != std::string::npos)
    fail(file, "a face has fewer than 3 vertices");
  if (warning.find("invalid vertex index") != std::string::npos ||
      warning.find("Vertex indices out of bounds") != std::string::npos) {
    check_indices(file, raw);  // names the face if tinyobj kept it
    fail(file, "a face refers to a vertex beyond the " + std::to_string(raw.positions.size()) +
                   " vertices of the mesh");
  }
  return raw;
}

// ---------------------------------------------------------------- PLY

enum class Scalar { I8, U8, I16, U16, I32, U32, F32, F64 };
constexpr std::size_t kScalarSize[] = {1, 1, 2, 2, 4, 4, 4, 8};

std::optional<Scalar> scalar_type(std::string_view name) {
  // Each type's classic and sized name, in the order of Scalar.
  static constexpr std::string_view kNames[][2] = {
      {"char", "int8"}, {"uchar", "uint8"}, {"short", "int16"},   {"ushort", "uint16"},
      {"int", "int32"}, {"uint", "uint32"}, {"float", "float32"}, {"double", "float64"}};
  for (int i = 0; i < 8; ++i)
    if (name == kNames[i][0] || name == kNames[i][1]) return static_cast<Scalar>(i);
  return std::nullopt;
}

struct PlyProperty {
  std::string name;
  bool is_list = false;
  Scalar count_type = Scalar::U8;  // lists only
  Scalar type = Scalar::F32;       // the value, or each list item
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
};

enum class Encoding { Ascii, LittleEndian, BigEndian };

struct PlyHeader {
  Encoding encoding = Encoding::Ascii;
  std::vector<PlyElement> elements;
  std::size_t body_offset = 0;  // first byte after the end_header line
  int line_count = 0;
};

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f'; }

PlyHeader parse_ply_header(const fs::path& file, std::string_view text) {
  if (!text.starts_with("ply\n") && !text.starts_with("ply\r\n"))
    fail(file, "not a PLY file (it does not start with 'ply')");
  PlyHeader header;
  bool have_format = false;
  std::size_t pos = 0;
  for (int line_no = 1;; ++line_no) {
    const std::size_t eol = text.find('\n', pos);
    if (eol == std::string_view::npos) fail(file, "truncated PLY header (no end_header line)");
    const std::string_view line = text.substr(pos, eol - pos);
    pos = eol + 1;
    std::istringstream words{std::string(line)};
    const std::vector<std::string> tok{std::istream_iterator<std::string>(words), {}};
    const auto bad_line = [&](const char* what) {
      fail(file, std::string(what) + " '" + std::string(line.substr(0, 80)) + "'", line_no);
    };
    if (line_no == 1 || tok.empty() || tok[0] == "comment" || tok[0] == "obj_info") continue;

    if (tok[0] == "end_header") {
      header.body_offset = pos;
      header.line_count = line_no;
      break;
    } else if (tok[0] == "format") {
      if (tok.size() != 3 || tok[2] != "1.0") bad_line("unsupported PLY format line");
      if (tok[1] == "ascii") header.encoding = Encoding::Ascii;
      else if (tok[1] == "binary_little_endian") header.encoding = Encoding::LittleEndian;
      else if (tok[1] == "binary_big_endian") header.encoding = Encoding::BigEndian;
      else bad_line("unsupported PLY format line");
      have_format = true;
    } else if (tok[0] == "element") {
      std::uint64_t count = 0;
      if (tok.size() != 3) bad_line("malformed PLY element line");
      const auto [end, ec] = std::from_chars(tok[2].data(), tok[2].data() + tok[2].size(), count);
      if (ec != std::errc() || end != tok[2].data() + tok[2].size()) bad_line("malformed PLY element line");
      header.elements.push_back({tok[1], count, {}});
    } else if (tok[0] == "property") {
      if (header.elements.empty()) bad_line("PLY property before any element");
      PlyProperty prop;
      prop.is_list = tok.size() == 5 && tok[1] == "list";
      if (!prop.is_list && tok.size() != 3) bad_line("malformed PLY property line");
      // The type names sit between "property" (and "list") and the property name.
      std::vector<Scalar> types;
      for (std::size_t i = prop.is_list ? 2 : 1; i + 1 < tok.size(); ++i) {
        const std::optional<Scalar> type = scalar_type(tok[i]);
        if (!type) fail(file, "unknown PLY property type '" + tok[i] + "'", line_no);
        types.push_back(*type);
      }
      prop.count_type = types.front();
      prop.type = types.back();
      prop.name = tok.back();
      header.elements.back().properties.push_back(std::move(prop));
    } else {
      fail(file, "unknown PLY header keyword '" + tok[0] + "'", line_no);
    }
  }
  if (!have_format) fail(file, "PLY header has no format line");
  return header;
}

template <typename T>
double decode(const unsigned char* bytes) {
  T value;
  std::memcpy(&value, bytes, sizeof value);
  return static_cast<double>(value);
}
// In the order of Scalar.
constexpr double (*kDecode[])(const unsigned char*) = {
    decode<std::int8_t>,  decode<std::uint8_t>,  decode<std::int16_t>, decode<std::uint16_t>,
    decode<std::int32_t>, decode<std::uint32_t>, decode<float>,        decode<double>};

// Reads the values of a PLY body one at a time, as doubles (exact for
// every PLY type). ASCII values are whitespace-separated tokens, one
// element per line as the format has it: blank lines between elements and
// "\r\n" or extra spaces are tolerated, but a value too many or too few on
// a line is reported at that line, not later where the shifted values no
// longer make sense.
class PlyBody {
 public:
  PlyBody(const fs::path& file, std::string_view body, Encoding encoding, int first_line)
      : file_(file), body_(body), encoding_(encoding), line_(first_line) {}

  // ASCII: moves to the start of the next element's line, past blank lines.
  void begin_element() {
    if (encoding_ != Encoding::Ascii) return;
    for (; pos_ < body_.size() && is_space(body_[pos_]); ++pos_)
      if (body_[pos_] == '\n') ++line_;
  }

  // False when the data ran out before the value, or (ASCII) the element's
  // line did (then at_line_end()).
  bool next(Scalar type, double& out) {
    if (encoding_ == Encoding::Ascii) return next_ascii(out);
    const std::size_t size = kScalarSize[static_cast<int>(type)];
    if (body_.size() - pos_ < size) return false;
    unsigned char bytes[8];
    std::memcpy(bytes, body_.data() + pos_, size);
    pos_ += size;
    if ((encoding_ == Encoding::LittleEndian) != (std::endian::native == std::endian::little))
      std::reverse(bytes, bytes + size);
    out = kDecode[static_cast<int>(type)](bytes);
    return true;
  }
  bool at_line_end() const { return pos_ < body_.size() && body_[pos_] == '\n'; }

  // ASCII: the first token left on the current line (after an element's
  // last value), or empty; moves past the line.
  std::string_view rest_of_line() {
    if (encoding_ != Encoding::Ascii) return {};
    skip_blanks();
    const std::size_t start = pos_;
    while (pos_ < body_.size() && !is_space(body_[pos_])) ++pos_;
    const std::string_view token = body_.substr(start, pos_ - start);
    if (token.empty() && pos_ < body_.size()) {  // at the '\n'
      ++pos_;
      ++line_;
    }
    return token;
  }

  // The current line for messages (ASCII), else 0 (none).
  int line() const { return encoding_ == Encoding::Ascii ? line_ : 0; }

 private:
  void skip_blanks() {
    while (pos_ < body_.size() && body_[pos_] != '\n' && is_space(body_[pos_])) ++pos_;
  }
  bool next_ascii(double& out) {
    skip_blanks();
    if (pos_ == body_.size() || body_[pos_] == '\n') return false;
    const std::size_t start = pos_;
    while (pos_ < body_.size() && !is_space(body_[pos_])) ++pos_;
    const std::string_view token = body_.substr(start, pos_ - start);
    const Number parsed = parse_number(token, out);
    if (parsed == Number::kMalformed)
      fail(file_, "malformed number '" + std::string(token.substr(0, 40)) + "'", line_);
    if (parsed == Number::kOverflow)
      fail(file_, "number '" + std::string(token.substr(0, 40)) + "' is out of range", line_);
    return true;
  }

  const fs::path& file_;
  std::string_view body_;
  Encoding encoding_;
  std::size_t pos_ = 0;
  int line_;  // ASCII only, for messages
};

// "x, y, z" or "list vertex_indices": an element's properties as a message shows them.
std::string property_names(const PlyElement& element) {
  std::string out;
  for (const PlyProperty& p : element.properties)
    out += (out.empty() ? "" : ", ") + std::string(p.is_list ? "list " : "") + p.name;
  return out;
}

std::string plural(const std::string& element) {
  if (element == "vertex") return "vertices";
  if (element == "face") return "faces";
  return "'" + element + "' elements";
}

RawMesh parse_ply(const fs::path& file, std::string_view text) {
  const PlyHeader header = parse_ply_header(file, text);

  // What each property of each element is for; everything else is skipped.
  enum Role { kSkip = -1, kX = 0, kY = 1, kZ = 2, kFaceIndices = 3, kNx = 4, kNy = 5, kNz = 6, kU = 7, kV = 8 };
  bool has_normals = false, has_uvs = false;
  std::vector<std::string> ignored;
  std::vector<std::vector<int>> roles;
  bool have_vertex = false, have_face = false;
  for (const PlyElement& element : header.elements) {
    std::vector<int>& role = roles.emplace_back(element.properties.size(), kSkip);
    const auto find = [&](std::initializer_list<std::string_view> names) -> int {
      for (std::size_t i = 0; i < element.properties.size(); ++i)
        for (const std::string_view name : names)
          if (element.properties[i].name == name) return static_cast<int>(i);
      return -1;
    };
    if (element.name == "vertex" && !have_vertex) {
      have_vertex = true;
      for (int axis : {kX, kY, kZ}) {
        const std::string name(1, "xyz"[axis]);
        const int i = find({name});
        if (i < 0 || element.properties[i].is_list)
          fail(file, "PLY vertex element has no scalar '" + name + "' property");
        role[i] = axis;
      }
      // Normals: all of nx ny nz, or none.
      const int normal[3] = {find({"nx"}), find({"ny"}), find({"nz"})};
      const int normal_count = (normal[0] >= 0) + (normal[1] >= 0) + (normal[2] >= 0);
      if (normal_count != 0 && normal_count != 3) ignored.push_back("an incomplete vertex normal (not all of nx, ny, nz)");
      if (normal_count == 3) {
        has_normals = true;
        for (int k = 0; k < 3; ++k) {
          if (element.properties[normal[k]].is_list) fail(file, "PLY vertex normal property is a list");
          role[normal[k]] = kNx + k;
        }
      }
      // Texture coordinates, by the names writers use.
      for (const auto& [u_name, v_name] : {std::pair{"u", "v"}, std::pair{"s", "t"},
                                           std::pair{"texture_u", "texture_v"}, std::pair{"texture_s", "texture_t"}}) {
        const int u = find({u_name}), v = find({v_name});
        if (u < 0 || v < 0 || has_uvs) continue;
        if (element.properties[u].is_list || element.properties[v].is_list)
          fail(file, "PLY vertex texture coordinate property is a list");
        has_uvs = true;
        role[u] = kU;
        role[v] = kV;
      }
      if (find({"red"}) >= 0 || find({"r"}) >= 0 || find({"diffuse_red"}) >= 0) ignored.push_back("per-vertex colours");
    } else if (element.name == "face" && !have_face) {
      have_face = true;
      const int i = find({"vertex_indices", "vertex_index"});
      if (i < 0 || !element.properties[i].is_list)
        fail(file, "PLY face element has no 'vertex_indices' list property");
      role[i] = kFaceIndices;
      if (find({"red"}) >= 0 || find({"r"}) >= 0) ignored.push_back("per-face colours");
      if (find({"texcoord"}) >= 0) ignored.push_back("per-face texture coordinates ('texcoord')");
    }
  }
  if (!have_vertex) fail(file, "PLY file has no 'vertex' element");
  if (!have_face) fail(file, "PLY file has no 'face' element");

  // Element counts the body cannot hold are refused before anything is read:
  // each element takes at least its scalars (binary) or a digit and a blank
  // per property (ASCII).
  const std::uint64_t body_bytes = text.size() - header.body_offset;
  for (const PlyElement& element : header.elements) {
    std::uint64_t least = 0;
    for (const PlyProperty& p : element.properties)
      least += header.encoding == Encoding::Ascii ? 2 : kScalarSize[static_cast<int>(p.is_list ? p.count_type : p.type)];
    if (least > 0 && element.count > body_bytes / least)
      fail(file, "the header declares " + std::to_string(element.count) + " " + plural(element.name) + ", more than the " +
                     std::to_string(body_bytes) + " bytes after it can hold");
  }

  RawMesh raw;
  raw.ignored = std::move(ignored);
  PlyBody body(file, text.substr(header.body_offset), header.encoding, header.line_count + 1);
  for (std::size_t e = 0; e < header.elements.size(); ++e) {
    const PlyElement& element = header.elements[e];
    const std::vector<int>& role = roles[e];
    const bool is_vertex = std::count(role.begin(), role.end(), kX) > 0;
    const bool is_face = std::count(role.begin(), role.end(), kFaceIndices) > 0;
    if (element.properties.empty()) continue;  // nothing stored, however large the count
    for (std::uint64_t i = 0; i < element.count; ++i) {
      const auto which = [&] { return element.name + " " + std::to_string(i); };  // for messages
      int values = 0;  // on this element's line so far
      body.begin_element();
      const auto read = [&](Scalar type, const PlyProperty& prop) {
        double value = 0.0;
        if (!body.next(type, value)) {
          if (body.at_line_end())
            fail(file, which() + " ends after " + std::to_string(values) + (values == 1 ? " value" : " values") +
                           ", inside its " + (prop.is_list ? "list '" : "property '") + prop.name +
                           "' (the header gives it: " + property_names(element) + "; ASCII PLY has one element per line)",
                 body.line());
          fail(file, "truncated: expected " + std::to_string(element.count) + " " + plural(element.name) +
                         ", found " + std::to_string(i));
        }
        ++values;
        return value;
      };
      vec3 position(0.0f), normal(0.0f);
      vec2 uv(0.0f);
      for (std::size_t p = 0; p < element.properties.size(); ++p) {
        const PlyProperty& prop = element.properties[p];
        if (!prop.is_list) {
          const auto value = static_cast<float>(read(prop.type, prop));
          if (role[p] >= kX && role[p] <= kZ) position[role[p]] = value;
          else if (role[p] >= kNx && role[p] <= kNz) normal[role[p] - kNx] = value;
          else if (role[p] == kU) uv.x = value;
          else if (role[p] == kV) uv.y = value;
          continue;
        }
        const double length = read(prop.count_type, prop);
        if (!(length >= 0.0 && length <= 1e9 && std::floor(length) == length))
          fail(file, "PLY " + which() + " has an invalid list length", body.line());
        if (role[p] == kFaceIndices && length < 3)
          fail(file, "face " + std::to_string(i) + " has " + std::to_string(static_cast<int>(length)) +
                         " vertices (at least 3 needed)", body.line());
        for (std::size_t k = 0; k < static_cast<std::size_t>(length); ++k) {
          const double value = read(prop.type, prop);
          if (role[p] != kFaceIndices) continue;
          if (!(std::floor(value) == value && std::abs(value) < 1e18))
            fail(file, "face " + std::to_string(i) + " has an invalid vertex index", body.line());
          raw.indices.push_back(static_cast<std::int64_t>(value));
        }
      }
      const int line = body.line();
      if (const std::string_view extra = body.rest_of_line(); !extra.empty())
        fail(file, which() + " has more values than the header gives it (" + property_names(element) +
                       "): the first extra is '" + std::string(extra.substr(0, 40)) +
                       "' (ASCII PLY has one element per line)",
             line);
      if (is_vertex) {
        raw.positions.push_back(position);
        if (has_normals) raw.normals.push_back(normal);
        if (has_uvs) raw.uvs.push_back(uv);
      }
      if (is_face) raw.face_start.push_back(raw.indices.size());
    }
  }
  // ASCII: a line beyond the elements the header declares (a count too small).
  body.begin_element();
  const int line = body.line();
  if (const std::string_view extra = body.rest_of_line(); !extra.empty())
    fail(file, "'" + std::string(extra.substr(0, 40)) +
                   "' after the last element the header declares (is an element count in the header too small?)",
         line);
  return raw;
}

}  // namespace

std::vector<char> read_file_maybe_gz(const std::filesystem::path& file) {
  // /dev/zero, a FIFO or a folder would be read for ever, or block.
  require_regular_file(file, "a mesh");
  const std::uint64_t limit = memory_limit_bytes();
  std::error_code size_error;
  if (const std::uintmax_t bytes = std::filesystem::file_size(file, size_error); !size_error && bytes > limit)
    fail(file, "the file has " + std::to_string(bytes / (1024 * 1024)) + " MB, more than the memory limit" +
                   memory_limit_note());
  errno = 0;
  const std::unique_ptr<gzFile_s, int (*)(gzFile)> gz(gzopen(file.string().c_str(), "rb"), gzclose);
  if (!gz) fail(file, std::string("cannot open file: ") + (errno ? std::strerror(errno) : "out of memory"));
  gzbuffer(gz.get(), 1 << 17);

  std::vector<char> data;
  std::size_t size = 0;
  while (true) {
    data.resize(size + (1 << 18));
    const int n = gzread(gz.get(), data.data() + size, static_cast<unsigned>(data.size() - size));
    int code = Z_OK;
    std::string_view message = gzerror(gz.get(), &code);  // mostly "<path>: <problem>"
    if (message.starts_with(file.string() + ": ")) message.remove_prefix(file.string().size() + 2);
    // At the end of the input, Z_BUF_ERROR means it stopped inside a gzip stream.
    if (n < 0 || (code != Z_OK && (code != Z_BUF_ERROR || n == 0))) {
      if (code == Z_ERRNO) fail(file, std::string("cannot read file: ") + std::strerror(errno));
      fail(file, "corrupt gzip data: " + std::string(message));
    }
    if (n == 0) break;
    size += static_cast<std::size_t>(n);
    // Counted as it inflates: a small .gz may expand to any size.
    if (size > limit)
      fail(file, "decompresses to more than " + std::to_string(limit / (1024 * 1024)) + " MB, the memory limit" +
                     memory_limit_note());
  }
  data.resize(size);
  return data;
}

vec2 TriangleMesh::uv_at(std::uint32_t t, vec2 b) const {
  using namespace width1;  // the generic step at width 1 (core/simd/texture_inputs-inl.h)
  F u, v;
  generic::uv_at(kScalar, lane1::M{has_uvs()}, F{b.x}, F{b.y}, corner_uvs(*this, t), u, v);
  return vec2(u.raw, v.raw);
}

std::vector<vec3> smooth_vertex_normals(const TriangleMesh& mesh) {
  std::vector<dvec3> sum(mesh.positions.size(), dvec3(0.0));
  for (const glm::uvec3& t : mesh.triangles) {
    const std::array<dvec3, 3> w = angle_weighted(mesh.positions[t.x], mesh.positions[t.y], mesh.positions[t.z]);
    for (int k = 0; k < 3; ++k) sum[t[k]] += w[k];
  }
  std::vector<vec3> normals(sum.size());
  for (std::size_t v = 0; v < sum.size(); ++v) {
    const double length = glm::length(sum[v]);
    normals[v] = length > 0.0 ? vec3(sum[v] / length) : vec3(0.0f, 0.0f, 1.0f);
  }
  return normals;
}

std::vector<std::pair<std::uint16_t, TriangleMesh>> split_by_face_material(TriangleMesh mesh) {
  std::vector<std::pair<std::uint16_t, TriangleMesh>> parts;
  // The triangles of each slot, in one pass (a file may have thousands of
  // materials); the last bucket holds kNoFileMaterial's.
  const std::size_t names = mesh.material_names.size();
  const auto bucket = [names](std::uint16_t slot) -> std::size_t {
    return slot == TriangleMesh::kNoFileMaterial ? names : slot;
  };
  std::vector<std::vector<std::uint32_t>> by_slot(names + 1);
  for (std::uint32_t t = 0; t < mesh.face_material.size(); ++t) {
    const std::uint16_t m = mesh.face_material[t];
    if (m != TriangleMesh::kNoFileMaterial && m >= names)
      throw std::invalid_argument("split_by_face_material: a face names material slot " + std::to_string(m) + " of " +
                                  std::to_string(names));
    by_slot[bucket(m)].push_back(t);
  }
  // kNoFileMaterial first (its faces come before every `usemtl`), then by
  // name; a mesh without face materials is all kNoFileMaterial.
  std::vector<std::uint16_t> slots;
  if (mesh.face_material.empty() || !by_slot[names].empty()) slots.push_back(TriangleMesh::kNoFileMaterial);
  for (std::size_t m = 0; m < names; ++m)
    if (!by_slot[m].empty()) slots.push_back(static_cast<std::uint16_t>(m));
  if (slots.size() == 1) {
    // All triangles in one part: the mesh as it is, without the copy.
    mesh.face_material.clear();
    mesh.material_names.clear();
    parts.emplace_back(slots[0], std::move(mesh));
    return parts;
  }
  constexpr std::uint32_t kUnused = 0xffffffffu;
  std::vector<std::uint32_t> remap(mesh.positions.size(), kUnused);
  for (const std::uint16_t slot : slots) {
    TriangleMesh part;
    std::vector<std::uint32_t> taken;  // vertices to reset in `remap`
    const auto vertex = [&](std::uint32_t v) {
      if (remap[v] == kUnused) {
        remap[v] = static_cast<std::uint32_t>(part.positions.size());
        taken.push_back(v);
        part.positions.push_back(mesh.positions[v]);
        if (mesh.has_normals()) part.normals.push_back(mesh.normals[v]);
        if (mesh.has_uvs()) part.uvs.push_back(mesh.uvs[v]);
        if (!mesh.tangents.empty()) part.tangents.push_back(mesh.tangents[v]);
      }
      return remap[v];
    };
    for (const std::uint32_t t : by_slot[bucket(slot)]) {
      const glm::uvec3& tri = mesh.triangles[t];
      const std::uint32_t a = vertex(tri.x), b = vertex(tri.y), c = vertex(tri.z);
      part.triangles.emplace_back(a, b, c);
    }
    for (const std::uint32_t v : taken) remap[v] = kUnused;
    parts.emplace_back(slot, std::move(part));
  }
  return parts;
}

TriangleMesh load_mesh(const std::filesystem::path& file, MeshLoadReport* report, const MeshLoadOptions& options) {
  std::string name = file.filename().string();
  std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return std::tolower(c); });
  if (name.ends_with(".gz")) name.resize(name.size() - 3);
  const std::size_t dot = name.rfind('.');
  const std::string extension = dot == std::string::npos ? "" : name.substr(dot);
  if (extension != ".obj" && extension != ".ply")
    fail(file, "unknown mesh format '" + extension + "' (expected .obj, .ply, optionally .gz)");

  const std::vector<char> data = read_file_maybe_gz(file);
  const std::string_view text(data.data(), data.size());
  RawMesh raw = extension == ".obj" ? parse_obj(file, text, options) : parse_ply(file, text);
  return finish(file, std::move(raw), report);
}

}  // namespace pathlab
