// Reading meshes from files: OBJ and STL (CGAL's IO), PLY (ASCII and binary) and ASCII OFF
// (our own readers).
#pragma once

#include <string>

#include "dcg/types.h"

namespace dcg {

/// Reads the triangle mesh at `path`. Polygons with more than 3 corners are fan-triangulated.
/// The result is the file's data as it is (no welding, no validation beyond what reading
/// needs: that is stage 0's job), except that face indices are checked to be in range.
///
/// Throws IoError when the file is missing, unreadable or of an unknown extension, and
/// InputError when it parses but holds no triangles or has out-of-range face indices.
/// Every message names the path.
Mesh read_mesh(const std::string& path);

}  // namespace dcg
