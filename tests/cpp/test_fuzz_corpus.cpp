// Replays the fuzzers' regression and seed inputs (tests/fuzz/corpus/<target>/) through the same
// entry points as the libFuzzer targets, so the plain and ASan + UBSan test builds (gcc, no
// libFuzzer) also check that the inputs that once crashed the readers or stage 0 are handled.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

// The two targets' sources, with their entry points renamed so that both fit in this binary.
#define LLVMFuzzerTestOneInput fuzz_read_mesh_one
#include "../fuzz/fuzz_read_mesh.cpp"
#undef LLVMFuzzerTestOneInput
#define LLVMFuzzerTestOneInput fuzz_prepare_one
#include "../fuzz/fuzz_prepare.cpp"
#undef LLVMFuzzerTestOneInput

#include "shapes.h"

namespace {

std::vector<std::filesystem::path> corpus(const std::string& target) {
  std::vector<std::filesystem::path> files;
  const std::filesystem::path dir = dcg::test::repo_file("tests/fuzz/corpus/" + target);
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.is_regular_file()) files.push_back(entry.path());
  }
  return files;
}

std::vector<std::uint8_t> bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(FuzzCorpus, ReadMeshInputsAreHandled) {
  const auto files = corpus("read_mesh");
  ASSERT_GE(files.size(), 6u);
  for (const auto& file : files) {
    SCOPED_TRACE(file.filename().string());
    const auto data = bytes(file);
    EXPECT_EQ(fuzz_read_mesh_one(data.data(), data.size()), 0);
  }
}

TEST(FuzzCorpus, PrepareInputsAreHandled) {
  const auto files = corpus("prepare");
  ASSERT_GE(files.size(), 3u);
  for (const auto& file : files) {
    SCOPED_TRACE(file.filename().string());
    const auto data = bytes(file);
    EXPECT_EQ(fuzz_prepare_one(data.data(), data.size()), 0);
  }
}

}  // namespace
