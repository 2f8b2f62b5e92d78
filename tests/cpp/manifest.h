// The public meshes' MANIFEST.tsv as the tests read it: one row per mesh with whether it is
// closed, its genus and the expected end points.
#pragma once

#include <cctype>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace dcg::test {

struct ManifestRow {
  std::string file;
  bool closed = false;
  int genus = 0;
  int low = 0, high = 0;  // expected end points: "2-3 + 1 loop" -> 2..3, "~2 + 4 loops" -> 2
  std::string expected;
};

inline std::vector<ManifestRow> read_manifest(const std::string& path) {
  std::vector<ManifestRow> rows;
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) {
    std::vector<std::string> cols;
    std::stringstream ss(line);
    std::string col;
    while (std::getline(ss, col, '\t')) cols.push_back(col);
    if (cols.size() < 10) continue;
    ManifestRow r;
    r.file = cols[0];
    r.closed = cols[6] == "yes";
    r.genus = cols[7].empty() ? 0 : std::stoi(cols[7]);
    r.expected = cols[9];
    const std::size_t i = r.expected.find_first_of("0123456789");
    if (i == std::string::npos) continue;
    std::size_t j = i;
    while (j < r.expected.size() && std::isdigit(static_cast<unsigned char>(r.expected[j]))) ++j;
    r.low = r.high = std::stoi(r.expected.substr(i, j - i));
    if (j + 1 < r.expected.size() && r.expected[j] == '-' &&
        std::isdigit(static_cast<unsigned char>(r.expected[j + 1]))) {
      r.high = std::stoi(r.expected.substr(j + 1));
    }
    rows.push_back(r);
  }
  return rows;
}

}  // namespace dcg::test
