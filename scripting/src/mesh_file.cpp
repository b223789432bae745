// OBJ and STL readers (see mesh_file.hpp and README.md, "Mesh files").
#include "mesh_file.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <map>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "messages.hpp"

namespace graspsim::scripting::detail {
namespace {

[[noreturn]] void fail_at(const std::string& where, const std::string& what) {
  throw ConversionError(where + ": " + what);
}

const char* not_regular(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

// The whole file, if it is a regular file of at most kMaxMeshFileBytes. Opened without blocking
// (a FIFO would wait for a writer) and checked on the open descriptor (the path cannot change
// between the check and the read); read to at most one byte over the limit, so a file that
// grows while it is read is refused too.
std::string read_bytes(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) fail_at(path, std::string("cannot open mesh file: ") + std::strerror(errno));
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  struct stat st {};
  if (::fstat(fd, &st) != 0) fail_at(path, std::string("cannot read mesh file: ") + std::strerror(errno));
  if (!S_ISREG(st.st_mode)) {
    fail_at(path, std::string("cannot read mesh file: it is ") + not_regular(st.st_mode) +
                      ", not a regular file (a mesh is read from a file; reading this could block or never end)");
  }
  const auto too_large = [&](const std::string& size) {
    fail_at(path, "mesh file too large: " + size + " bytes, over the limit of " + std::to_string(kMaxMeshFileBytes) +
                      " bytes (64 MiB; README \"Mesh files\")");
  };
  if (static_cast<std::uint64_t>(st.st_size) > kMaxMeshFileBytes) too_large(std::to_string(st.st_size));
  std::string bytes;
  char buffer[1 << 16];
  for (;;) {
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) fail_at(path, std::string("cannot read mesh file: ") + std::strerror(errno));
    if (n == 0) break;
    bytes.append(buffer, static_cast<std::size_t>(n));
    if (bytes.size() > kMaxMeshFileBytes) too_large("more than " + std::to_string(kMaxMeshFileBytes));
  }
  return bytes;
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> words;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    const std::size_t start = i;
    while (i < line.size() && !std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    if (i > start) words.push_back(line.substr(start, i - start));
  }
  return words;
}

// Lines without their end ("\n" or "\r\n"), numbered from 1 by position.
std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::size_t start = 0;
  while (start <= text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(start, end - start);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    lines.push_back(std::move(line));
    start = end + 1;
  }
  return lines;
}

double parse_number(const std::string& word, const std::string& where) {
  double x = 0.0;
  const char* first = word.data();
  const char* last = first + word.size();
  if (first != last && *first == '+') ++first;   // from_chars refuses a leading '+'
  const auto [end, error] = std::from_chars(first, last, x);
  if (error != std::errc() || end != last) fail_at(where, "bad number '" + word + "'");
  if (!std::isfinite(x)) fail_at(where, "the number '" + word + "' is not finite");
  return x;
}

long parse_index(const std::string& word, const std::string& where) {
  long i = 0;
  const char* first = word.data();
  const char* last = first + word.size();
  const auto [end, error] = std::from_chars(first, last, i);
  if (error != std::errc() || end != last) fail_at(where, "bad vertex index '" + word + "'");
  return i;
}

// Merges vertices at exactly the same position and drops triangles left with a repeated corner.
MeshFile assemble(const std::vector<Vec3>& points, const std::vector<std::array<int, 3>>& triangles,
                  const std::vector<std::string>& origin) {
  MeshFile out;
  std::map<std::array<double, 3>, int> index_of;   // -0.0 and 0.0 compare equal: one vertex
  std::vector<int> merged(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const std::array<double, 3> key{points[i].x(), points[i].y(), points[i].z()};
    const auto [it, fresh] = index_of.emplace(key, static_cast<int>(out.mesh.vertices.size()));
    if (fresh) out.mesh.vertices.push_back(points[i]);
    merged[i] = it->second;
  }
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const std::array<int, 3> tri{merged[triangles[t][0]], merged[triangles[t][1]], merged[triangles[t][2]]};
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[2] == tri[0]) continue;
    out.mesh.triangles.push_back(tri);
    out.origin.push_back(origin[t]);
  }
  return out;
}

MeshFile read_obj(const std::string& path, const std::string& text) {
  std::vector<Vec3> points;
  std::vector<std::array<int, 3>> triangles;
  std::vector<std::string> origin;
  struct Pending { long index; std::string where; };   // positive indices, checked at the end
  std::vector<std::array<Pending, 3>> faces;
  const std::vector<std::string> lines = lines_of(text);
  for (std::size_t n = 0; n < lines.size(); ++n) {
    const std::string where = path + ":" + std::to_string(n + 1);
    std::string line = lines[n];
    const std::size_t hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    const std::vector<std::string> w = split(line);
    if (w.empty()) continue;
    const std::string& key = w[0];
    if (key == "v") {
      if (w.size() < 4 || w.size() > 7) {
        fail_at(where, "a vertex needs 'v x y z' (got " + std::to_string(w.size() - 1) + " numbers)");
      }
      points.emplace_back(parse_number(w[1], where), parse_number(w[2], where), parse_number(w[3], where));
      for (std::size_t i = 4; i < w.size(); ++i) parse_number(w[i], where);
    } else if (key == "f") {
      if (w.size() < 4) fail_at(where, "a face needs at least 3 vertices (got " + std::to_string(w.size() - 1) + ")");
      std::vector<long> refs;
      for (std::size_t i = 1; i < w.size(); ++i) {
        const std::string v = w[i].substr(0, w[i].find('/'));   // v, v/vt, v/vt/vn, v//vn
        const long index = parse_index(v, where);
        if (index == 0) fail_at(where, "vertex index 0 (OBJ counts from 1, or from -1 backwards)");
        if (index < 0) {
          if (index < -static_cast<long>(points.size())) {   // not -index: overflows at LONG_MIN
            fail_at(where, "vertex index " + v + " is out of range (" + std::to_string(points.size()) +
                           " vertices so far)");
          }
          refs.push_back(static_cast<long>(points.size()) + index);
        } else {
          refs.push_back(index - 1);
        }
      }
      for (std::size_t i = 1; i + 1 < refs.size(); ++i) {   // a fan from the first corner
        triangles.push_back({0, 0, 0});
        origin.push_back(where);
        faces.push_back({Pending{refs[0], where}, Pending{refs[i], where}, Pending{refs[i + 1], where}});
      }
    } else if (key == "vt" || key == "vn" || key == "vp" || key == "o" || key == "g" || key == "s" ||
               key == "usemtl" || key == "mtllib") {
      continue;
    } else {
      fail_at(where, "unsupported statement '" + key + "' (only v and f are read; vt, vn, vp, o, g, "
                     "s, usemtl and mtllib are ignored)");
    }
  }
  for (std::size_t t = 0; t < faces.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const Pending& p = faces[t][k];
      if (p.index >= static_cast<long>(points.size())) {
        fail_at(p.where, "vertex index " + std::to_string(p.index + 1) + " is out of range (the file "
                         "has " + std::to_string(points.size()) + " vertices)");
      }
      triangles[t][k] = static_cast<int>(p.index);
    }
  }
  return assemble(points, triangles, origin);
}

MeshFile read_ascii_stl(const std::string& path, const std::string& text) {
  std::vector<Vec3> points;
  std::vector<std::array<int, 3>> triangles;
  std::vector<std::string> origin;
  const std::vector<std::string> lines = lines_of(text);
  bool in_facet = false;
  int corners = 0;
  std::string facet_where = path;
  for (std::size_t n = 0; n < lines.size(); ++n) {
    const std::string where = path + ":" + std::to_string(n + 1);
    const std::vector<std::string> w = split(lines[n]);
    if (w.empty()) continue;
    const std::string& key = w[0];
    if (key == "solid" || key == "endsolid" || key == "outer" || key == "endloop") continue;
    if (key == "facet") {
      if (in_facet) fail_at(where, "'facet' before the previous facet's 'endfacet'");
      in_facet = true;
      corners = 0;
      facet_where = where;
    } else if (key == "vertex") {
      if (!in_facet) fail_at(where, "'vertex' outside a facet");
      if (w.size() != 4) fail_at(where, "a vertex needs 'vertex x y z'");
      if (++corners > 3) fail_at(where, "a facet has more than 3 vertices");
      points.emplace_back(parse_number(w[1], where), parse_number(w[2], where), parse_number(w[3], where));
    } else if (key == "endfacet") {
      if (!in_facet) fail_at(where, "'endfacet' without 'facet'");
      if (corners != 3) fail_at(facet_where, "a facet needs 3 vertices (got " + std::to_string(corners) + ")");
      const int last = static_cast<int>(points.size());
      triangles.push_back({last - 3, last - 2, last - 1});
      origin.push_back(facet_where);
      in_facet = false;
    } else {
      fail_at(where, "unexpected '" + key + "' in an ASCII STL file");
    }
  }
  if (in_facet) fail_at(facet_where, "the facet has no 'endfacet'");
  return assemble(points, triangles, origin);
}

MeshFile read_binary_stl(const std::string& path, const std::string& bytes, std::uint32_t count) {
  static_assert(std::endian::native == std::endian::little, "binary STL is little-endian");
  std::vector<Vec3> points;
  std::vector<std::array<int, 3>> triangles;
  std::vector<std::string> origin;
  for (std::uint32_t t = 0; t < count; ++t) {
    const std::string where = path + ": triangle " + std::to_string(t + 1);
    const char* record = bytes.data() + 84 + 50 * static_cast<std::size_t>(t);
    for (int k = 0; k < 3; ++k) {
      float xyz[3];
      std::memcpy(xyz, record + 12 + 12 * k, sizeof xyz);
      if (!std::isfinite(xyz[0]) || !std::isfinite(xyz[1]) || !std::isfinite(xyz[2])) {
        fail_at(where, "vertex " + std::to_string(k + 1) + " is not finite");
      }
      points.emplace_back(xyz[0], xyz[1], xyz[2]);
    }
    const int last = static_cast<int>(points.size());
    triangles.push_back({last - 3, last - 2, last - 1});
    origin.push_back(where);
  }
  return assemble(points, triangles, origin);
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

}  // namespace

MeshFile read_mesh_file(const std::string& path) {
  const std::size_t dot = path.find_last_of('.');
  const std::string ext = dot == std::string::npos ? "" : lower(path.substr(dot));
  if (ext != ".obj" && ext != ".stl") {
    fail_at(path, "unknown mesh file type '" + ext + "' (use .obj or .stl)");
  }
  const std::string bytes = read_bytes(path);
  if (ext == ".obj") return read_obj(path, bytes);
  if (bytes.size() >= 84) {
    std::uint32_t count = 0;
    std::memcpy(&count, bytes.data() + 80, sizeof count);
    if (bytes.size() == 84 + 50 * static_cast<std::uint64_t>(count)) return read_binary_stl(path, bytes, count);
  }
  const std::size_t first = bytes.find_first_not_of(" \t\r\n");
  if (first != std::string::npos && bytes.compare(first, 5, "solid") == 0) return read_ascii_stl(path, bytes);
  std::string size_note;
  if (bytes.size() >= 84) {
    std::uint32_t count = 0;
    std::memcpy(&count, bytes.data() + 80, sizeof count);
    size_note = ", and its size, " + std::to_string(bytes.size()) + " bytes, is not 84 + 50 x " +
                std::to_string(count) + " (the triangle count in its header) as a binary STL's is";
  } else {
    size_note = ", and it is too short for a binary STL (" + std::to_string(bytes.size()) + " bytes, fewer than 84)";
  }
  fail_at(path, "not an STL file: it does not start with 'solid' as an ASCII STL does" + size_note);
}

std::string mesh_location(const MeshFile& file, const std::string& path, int triangle) {
  if (triangle >= 0 && triangle < static_cast<int>(file.origin.size())) return file.origin[triangle] + ": ";
  return path + ": ";
}

}  // namespace graspsim::scripting::detail
