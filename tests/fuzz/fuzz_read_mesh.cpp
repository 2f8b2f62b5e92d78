// libFuzzer target: dcg::read_mesh on arbitrary bytes. The first byte picks the format (OBJ,
// OFF, PLY or STL, by the file's extension); the rest is the file's content, written to a
// temporary file since the reader takes a path. Expected failures are dcg::InputError and
// dcg::IoError; anything else (a crash, a sanitizer report, another exception) is a finding.
//
// Build: cmake -DDCG_FUZZ=ON with clang (see CMakeLists.txt); run: scripts/run-fuzz.sh.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

#include "dcg/errors.h"
#include "dcg/io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  static const char* const kExtensions[] = {".obj", ".off", ".ply", ".stl"};
  const std::string path =
      "/tmp/dcg-fuzz-read-" + std::to_string(getpid()) + kExtensions[data[0] % 4];
  {
    std::FILE* file = std::fopen(path.c_str(), "wb");
    if (!file) return 0;
    if (size > 1) std::fwrite(data + 1, 1, size - 1, file);
    std::fclose(file);
  }
  try {
    const dcg::Mesh mesh = dcg::read_mesh(path);
    // What read_mesh promises: n x 3 faces with indices into V.
    for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
      for (int k = 0; k < 3; ++k) {
        if (mesh.F(f, k) < 0 || mesh.F(f, k) >= mesh.V.rows()) __builtin_trap();
      }
    }
  } catch (const dcg::InputError&) {
  } catch (const dcg::IoError&) {
  }
  std::remove(path.c_str());
  return 0;
}
