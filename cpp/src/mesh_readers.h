// Internal: the PLY and OFF readers behind dcg::read_mesh (ply_reader.cpp, off_reader.cpp say
// why they are ours and not CGAL's).
#pragma once

#include <string>
#include <vector>

#include "dcg/types.h"

namespace dcg::internal {

/// Reads a PLY file (ascii, binary_little_endian or binary_big_endian): the x, y, z of element
/// "vertex" and the index list "vertex_indices" (or "vertex_index") of element "face",
/// fan-triangulated; every other element and property is read past. Throws InputError, naming
/// `path`, for a malformed header, a body that ends early or holds what the header does not
/// allow, and a face index outside the vertices. Every allocation is bounded by the file's size.
Mesh read_ply(const std::string& path);

/// Reads an ASCII OFF file ([ST][C][N]OFF: the first 3 numbers of each vertex line are its
/// coordinates, the rest of the line is read past; each face line is its corner count and that
/// many vertex indices, fan-triangulated, then optional colour values). Comments (#) are
/// dropped. Throws InputError, naming `path`, for binary OFF, 4D/nD points, counts the file
/// cannot hold, a file that ends early, and anything that is not a number where one is needed.
Mesh read_off(const std::string& path);

/// The mesh of a reader's x y z triples and triangle corners (3 per triangle, as read: any
/// double); InputError when there is no triangle or a corner is not an index into the vertices.
Mesh assemble_mesh(const std::string& path, const std::vector<double>& coordinates,
                   const std::vector<double>& corners);

}  // namespace dcg::internal
