// Internal: the PLY and OFF readers behind dcg::read_mesh (ply_reader.cpp, off_reader.cpp say
// why they are ours and not CGAL's).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace dcg::internal {

/// What a reader gives dcg::read_mesh (io.cpp), which checks the indices and fan-triangulates
/// for every format alike: x y z per vertex, and each face's vertex indices as read (doubles,
/// unchecked) one face after the other, `sizes` saying how many each face has.
struct PolygonSoup {
  std::vector<double> coordinates;
  std::vector<double> corners;
  std::vector<std::size_t> sizes;
};

/// Reads a PLY file (ascii, binary_little_endian or binary_big_endian): the x, y, z of element
/// "vertex" and the index list "vertex_indices" (or "vertex_index") of element "face"; every
/// other element and property is read past. Throws InputError, naming `path`, for a malformed
/// header and a body that ends early or holds what the header does not allow. Every allocation
/// is bounded by the file's size.
PolygonSoup read_ply(const std::string& path);

/// Reads an ASCII OFF file ([ST][C][N]OFF: the first 3 numbers of each vertex line are its
/// coordinates, the rest of the line is read past; each face line is its corner count and that
/// many vertex indices, then optional colour values). Comments (#) are
/// dropped. Throws InputError, naming `path`, for binary OFF, 4D/nD points, counts the file
/// cannot hold, a file that ends early, and anything that is not a number where one is needed.
PolygonSoup read_off(const std::string& path);

}  // namespace dcg::internal
