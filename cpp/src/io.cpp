// Mesh files through CGAL's polygon-soup IO (this translation unit is the only one that
// includes it). See dcg/io.h.
#include "dcg/io.h"

#include <CGAL/IO/polygon_soup_io.h>
#include <CGAL/Simple_cartesian.h>

#include <algorithm>
#include <cstdint>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "dcg/errors.h"

namespace dcg {
namespace {

using Kernel = CGAL::Simple_cartesian<double>;

std::string lower_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

// CGAL's PLY reader trusts the header: it adds each "property" to the last "element" seen
// without checking that there is one (PLY_reader.h, init), and reads the vertex coordinates
// and the face indices through a dynamic_cast to the types it expects, dereferencing the null
// pointer when the header declares another (a uchar z, float indices). Both crash, and an
// element count of -1 hangs it (found by fuzzing: tests/fuzz/corpus/read_mesh/crash-ply-*). This checks the header's text first;
// everything else is left to CGAL.
void check_ply_header(const std::string& path, std::uintmax_t file_size) {
  static const std::set<std::string> reals = {"float", "float32", "double", "float64"};
  static const std::set<std::string> integers = {"char",   "int8",  "uchar", "uint8",
                                                 "short",  "int16", "ushort", "uint16",
                                                 "int",    "int32", "uint",  "uint32"};
  std::ifstream in(path, std::ios::binary);
  std::string line, element;
  for (int number = 1; number <= 100000 && std::getline(in, line); ++number) {
    std::istringstream words(line);
    std::string keyword;
    words >> keyword;
    if (keyword == "end_header") return;
    auto fail = [&](const std::string& why) {
      throw InputError(path + ": line " + std::to_string(number) + " of the PLY header " + why);
    };
    if (keyword == "element") {
      // A count the file cannot hold (or -1, read as 2^64 - 1) kept CGAL reading at the end of
      // the file forever (found by fuzzing): at most one element per byte of the file.
      std::string count;
      if (!(words >> element >> count)) fail("names no element and count");
      if (count.empty() || count.size() > 18 ||
          count.find_first_not_of("0123456789") != std::string::npos ||
          std::stoull(count) > file_size) {
        fail("gives element " + element + " the count '" + count + "', not a number of " +
             "elements its " + std::to_string(file_size) + " bytes can hold");
      }
    } else if (keyword == "property") {
      if (element.empty()) fail("declares a property before any element");
      std::string type, name;
      words >> type >> name;
      if (type == "list") {
        std::string size_type = name, index_type;
        words >> index_type >> name;
        if (element == "face" && (name == "vertex_indices" || name == "vertex_index") &&
            (!integers.count(size_type) || !integers.count(index_type))) {
          fail("gives the face indices a type that is not an integer");
        }
      } else if (element == "vertex" && (name == "x" || name == "y" || name == "z") &&
                 !reals.count(type)) {
        fail("gives vertex coordinate " + name + " the type '" + type +
             "' (float or double expected)");
      }
    }
  }
}

// CGAL's OFF reader trusts the numbers of an ASCII file: a header count or a face's corner
// count is turned into an allocation as it is (a ten-byte line can ask for exabytes: a crash
// under the sanitizers, bad_alloc or the OOM killer without them), and face indices are read
// as doubles and cast to size_t (undefined for 1e100). Found by fuzzing
// (tests/fuzz/corpus/read_mesh/crash-off-*). This scans an ASCII OFF file first and refuses
// counts the file cannot hold and face entries that are not indices into the vertices. A file
// this scan cannot follow (binary OFF, coordinates over several lines) is left to CGAL.
void check_off(const std::string& path, std::uintmax_t file_size) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  std::vector<std::string> words;
  auto next_line = [&]() {  // the next line with words, comments dropped
    while (std::getline(in, line)) {
      const auto hash = line.find('#');
      if (hash != std::string::npos) line.resize(hash);
      std::istringstream ss(line);
      words.clear();
      for (std::string w; ss >> w;) words.push_back(w);
      if (!words.empty()) return true;
    }
    return false;
  };
  auto as_count = [](const std::string& w, long long& value) {
    if (w.empty() || w.size() > 18 || w.find_first_not_of("0123456789") != std::string::npos) {
      return false;
    }
    value = std::stoll(w);
    return true;
  };
  if (!next_line()) return;
  // The keyword: [ST][C][N][4][n]OFF, optionally followed by BINARY; CGAL also reads a file
  // without it (the counts come first).
  std::vector<std::string> counts = words;
  const std::string keyword = words[0];
  const auto at = keyword.find("OFF");
  if (at != std::string::npos) {
    if (at + 3 != keyword.size()) {
      throw InputError(path + ": the OFF header's first word '" + keyword + "' is not OFF");
    }
    if (keyword.find_first_of("4n") < at) {
      throw InputError(path + ": " + keyword + " files (4D or nD points) are not supported");
    }
    counts.erase(counts.begin());
    if (!counts.empty() && counts[0] == "BINARY") return;  // left to CGAL
    if (counts.empty()) {
      if (!next_line()) return;
      counts = words;
    }
  }
  long long nv = 0, nf = 0;
  if (counts.size() < 2 || !as_count(counts[0], nv) || !as_count(counts[1], nf)) {
    throw InputError(path + ": the OFF header's vertex and face counts are not whole numbers");
  }
  // The edge count is unused, but CGAL doubles it as an int: more than 1e9 overflows.
  if (counts.size() >= 3) {
    std::string digits = counts[2].substr(0, counts[2].find_first_not_of("0123456789"));
    digits.erase(0, std::min(digits.find_first_not_of('0'), digits.size()));
    if (digits.size() > 9) {
      throw InputError(path + ": the OFF header's edge count " + counts[2] + " is too large");
    }
  }
  // Each vertex takes at least 6 bytes ("0 0 0\n"), each face at least 8 ("3 0 1 2\n").
  if (nv > static_cast<long long>(file_size / 6) || nf > static_cast<long long>(file_size / 8)) {
    throw InputError(path + ": the OFF header announces " + std::to_string(nv) + " vertices and " +
                     std::to_string(nf) + " faces, more than its " + std::to_string(file_size) +
                     " bytes can hold");
  }
  for (long long i = 0; i < nv; ++i) {
    if (!next_line()) return;
    if (words.size() < 3) return;  // coordinates over several lines: leave it to CGAL
  }
  for (long long f = 0; f < nf; ++f) {
    if (!next_line()) return;
    long long corners = 0;
    if (!as_count(words[0], corners) || corners + 1 > static_cast<long long>(words.size())) {
      throw InputError(path + ": OFF face " + std::to_string(f) + " does not start with its "
                       "number of corners followed by that many vertex indices");
    }
    for (long long k = 1; k <= corners; ++k) {
      long long index = 0;
      if (!as_count(words[k], index) || index >= nv) {
        throw InputError(path + ": OFF face " + std::to_string(f) + " has vertex index '" +
                         words[k] + "', not an index into its " + std::to_string(nv) +
                         " vertices");
      }
    }
  }
}

}  // namespace

Mesh read_mesh(const std::string& path) {
  namespace fs = std::filesystem;
  const fs::path p(path);
  std::error_code ec;
  if (!fs::exists(p, ec)) throw IoError(path + ": no such file");
  if (fs::is_directory(p, ec)) throw IoError(path + ": is a directory, not a mesh file");
  {
    std::ifstream probe(path, std::ios::binary);
    if (!probe) throw IoError(path + ": cannot be opened for reading");
  }
  const std::string ext = lower_extension(p);
  if (ext != ".obj" && ext != ".off" && ext != ".ply" && ext != ".stl") {
    throw IoError(path + ": unsupported format '" + ext + "' (use .obj, .off, .ply or .stl)");
  }
  if (fs::file_size(p, ec) == 0) throw InputError(path + ": the file is empty");

  // Faces as vectors of indices: reading into std::array<size_t, 3> corrupts the heap (the OBJ
  // reader grows faces one index at a time; see ENVIRONMENT.md).
  if (ext == ".ply") check_ply_header(path, fs::file_size(p, ec));
  if (ext == ".off") check_off(path, fs::file_size(p, ec));
  std::vector<Kernel::Point_3> points;
  std::vector<std::vector<std::size_t>> polygons;
  bool ok = false;
  try {
    ok = CGAL::IO::read_polygon_soup(path, points, polygons, CGAL::parameters::verbose(false));
  } catch (const std::exception& e) {
    throw IoError(path + ": cannot be parsed (" + e.what() + ")");
  }
  if (!ok && points.empty()) throw IoError(path + ": cannot be parsed as " + ext.substr(1));
  if (points.empty() || polygons.empty()) {
    throw InputError(path + ": holds no triangles (" + std::to_string(points.size()) +
                     " vertices, " + std::to_string(polygons.size()) + " faces)");
  }

  Mesh mesh;
  mesh.V.resize(static_cast<Eigen::Index>(points.size()), 3);
  for (std::size_t i = 0; i < points.size(); ++i) {
    mesh.V.row(static_cast<Eigen::Index>(i)) << points[i].x(), points[i].y(), points[i].z();
  }
  std::size_t triangles = 0;
  for (const auto& poly : polygons) triangles += poly.size() >= 3 ? poly.size() - 2 : 0;
  if (triangles == 0) throw InputError(path + ": holds no faces with 3 or more corners");
  mesh.F.resize(static_cast<Eigen::Index>(triangles), 3);
  Eigen::Index t = 0;
  for (std::size_t f = 0; f < polygons.size(); ++f) {
    const auto& poly = polygons[f];
    for (std::size_t index : poly) {
      if (index >= points.size()) {
        throw InputError(path + ": face " + std::to_string(f) + " refers to vertex " +
                         std::to_string(index) + " but the file has only " +
                         std::to_string(points.size()) + " vertices");
      }
    }
    for (std::size_t k = 1; k + 1 < poly.size(); ++k) {  // fan triangulation
      mesh.F.row(t++) << static_cast<int>(poly[0]), static_cast<int>(poly[k]),
          static_cast<int>(poly[k + 1]);
    }
  }
  return mesh;
}

}  // namespace dcg
