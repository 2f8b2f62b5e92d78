// Our own OFF reader. CGAL's trusts the numbers of the file: a header count or a face's corner
// count became an allocation as it was (a ten-byte line could ask for exabytes), the edge count
// was doubled as an int (overflow), and face indices were read as doubles and cast to size_t
// (undefined for 1e100); its comment handling differs from the header scan we had in front of
// it, which let an overflowing edge count through. Found by fuzzing:
// tests/fuzz/corpus/read_mesh/crash-off-*. Here every count is checked against what the file
// can hold before anything is allocated, and every value is parsed and checked as it is read.
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "dcg/errors.h"
#include "mesh_readers.h"

namespace dcg::internal {
namespace {

// The file's lines that hold words, comments (from '#' to the end of the line) dropped.
class OffLines {
 public:
  explicit OffLines(const std::string& path) : in_(path, std::ios::binary) {
    if (!in_) throw IoError(path + ": cannot be opened for reading");
  }

  /// The next line with words, split into `words`; false at the end of the file.
  bool next(std::vector<std::string>& words) {
    while (std::getline(in_, line_)) {
      ++number_;
      const auto hash = line_.find('#');
      if (hash != std::string::npos) line_.resize(hash);
      std::istringstream ss(line_);
      words.clear();
      for (std::string w; ss >> w;) words.push_back(w);
      if (!words.empty()) return true;
    }
    return false;
  }
  int number() const { return number_; }

 private:
  std::ifstream in_;
  std::string line_;
  int number_ = 0;
};

bool whole_number(const std::string& word, long long& value) {
  if (word.empty() || word.size() > 18 ||
      word.find_first_not_of("0123456789") != std::string::npos) {
    return false;
  }
  value = std::stoll(word);
  return true;
}

bool real_number(const std::string& word, double& value) {
  char* stop = nullptr;
  value = std::strtod(word.c_str(), &stop);
  return !word.empty() && stop == word.c_str() + word.size();
}

}  // namespace

PolygonSoup read_off(const std::string& path) {
  std::error_code ec;
  OffLines lines(path);
  std::vector<std::string> words;
  auto fail = [&](const std::string& why) {
    throw InputError(path + ": line " + std::to_string(lines.number()) + " of the OFF file " + why);
  };
  if (!lines.next(words)) throw InputError(path + ": holds no OFF header");
  // The keyword [ST][C][N][4][n]OFF, optionally followed by the counts or BINARY; like CGAL,
  // a file without it (the counts first) is accepted.
  std::vector<std::string> counts = words;
  const std::string keyword = words[0];
  const auto at = keyword.find("OFF");
  if (at != std::string::npos) {
    if (at + 3 != keyword.size() || keyword.find_first_not_of("STCN4n") < at) {
      fail("starts with '" + keyword.substr(0, 40) + "', not an OFF keyword");
    }
    if (keyword.find_first_of("4n") < at) {
      fail("is a " + keyword + " file (4D or nD points): not supported");
    }
    counts.erase(counts.begin());
    if (!counts.empty() && counts[0] == "BINARY") {
      fail("is binary OFF: not supported (save it as ASCII OFF, PLY or OBJ)");
    }
    if (counts.empty() && !lines.next(counts)) fail("ends before its vertex and face counts");
  }
  long long nv = 0, nf = 0;
  if (counts.size() < 2 || !whole_number(counts[0], nv) || !whole_number(counts[1], nf)) {
    fail("does not give the vertex and face counts as whole numbers");
  }
  // Each vertex takes at least 6 bytes ("0 0 0\n"), each face at least 8 ("3 0 1 2\n").
  const auto size = static_cast<long long>(std::filesystem::file_size(path, ec));
  if (nv > size / 6 || nf > size / 8) {
    fail("announces " + std::to_string(nv) + " vertices and " + std::to_string(nf) +
         " faces, more than its " + std::to_string(size) + " bytes can hold");
  }

  PolygonSoup soup;
  soup.coordinates.reserve(static_cast<std::size_t>(3 * nv));
  for (long long i = 0; i < nv; ++i) {
    if (!lines.next(words)) {
      fail("ends after " + std::to_string(i) + " of its " + std::to_string(nv) + " vertices");
    }
    if (words.size() < 3) fail("gives vertex " + std::to_string(i) + " fewer than 3 coordinates");
    for (int k = 0; k < 3; ++k) {
      double value = 0;
      if (!real_number(words[k], value)) {
        fail("has '" + words[k].substr(0, 40) + "' where a coordinate of vertex " +
             std::to_string(i) + " is expected");
      }
      soup.coordinates.push_back(value);
    }
  }
  for (long long f = 0; f < nf; ++f) {
    if (!lines.next(words)) {
      fail("ends after " + std::to_string(f) + " of its " + std::to_string(nf) + " faces");
    }
    long long n = 0;
    if (!whole_number(words[0], n) || n + 1 > static_cast<long long>(words.size())) {
      fail("does not give face " + std::to_string(f) +
           " as its number of corners followed by that many vertex indices");
    }
    for (long long k = 1; k <= n; ++k) {
      long long index = 0;
      if (!whole_number(words[static_cast<std::size_t>(k)], index) || index >= nv) {
        fail("gives face " + std::to_string(f) + " the vertex index '" +
             words[static_cast<std::size_t>(k)].substr(0, 40) + "', not an index into its " +
             std::to_string(nv) + " vertices");
      }
      soup.corners.push_back(static_cast<double>(index));
    }
    soup.sizes.push_back(static_cast<std::size_t>(n));
  }
  return soup;
}

}  // namespace dcg::internal
