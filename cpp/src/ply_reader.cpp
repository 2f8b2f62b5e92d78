// Our own PLY reader. CGAL's trusts the file: a property before any element, a coordinate or
// an index of an unexpected type, a count of -1, and a face whose corner count is read as a
// 32-bit int all crashed it, hung it or made it allocate gigabytes (found by fuzzing:
// tests/fuzz/corpus/read_mesh/*-ply-*). Here the header is checked first and the body is read
// one value at a time, so that no count the file cannot hold turns into an allocation.
#include "mesh_readers.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "dcg/errors.h"

namespace dcg::internal {
namespace {

enum class Format { kAscii, kLittleEndian, kBigEndian };

std::string number_text(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

struct ScalarType {
  const char* name;
  const char* alias;
  int bytes;
  bool integer;
  bool is_signed;
};

// PLY's scalar types, by both of their names.
constexpr ScalarType kTypes[] = {
    {"char", "int8", 1, true, true},      {"uchar", "uint8", 1, true, false},
    {"short", "int16", 2, true, true},    {"ushort", "uint16", 2, true, false},
    {"int", "int32", 4, true, true},      {"uint", "uint32", 4, true, false},
    {"float", "float32", 4, false, true}, {"double", "float64", 8, false, true},
};

const ScalarType* find_type(const std::string& name) {
  for (const ScalarType& t : kTypes) {
    if (name == t.name || name == t.alias) return &t;
  }
  return nullptr;
}

struct Property {
  std::string name;
  const ScalarType* type = nullptr;       // the value's type (a list's items)
  const ScalarType* size_type = nullptr;  // non-null for a list
};

struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::vector<Property> properties;
};

struct Header {
  Format format = Format::kAscii;
  std::vector<Element> elements;
  std::size_t body_offset = 0;  // the byte after end_header's line
};

Header parse_header(const std::string& path, const std::string& data) {
  Header header;
  bool have_format = false;
  std::size_t pos = 0;
  for (int number = 1;; ++number) {
    auto fail = [&](const std::string& why) {
      throw InputError(path + ": line " + std::to_string(number) + " of the PLY header " + why);
    };
    if (pos >= data.size()) fail("is missing: the file ends before end_header");
    if (number > 100000) fail("is past 100000 lines: no end_header");
    std::size_t end = data.find('\n', pos);
    if (end == std::string::npos) end = data.size();
    std::string line = data.substr(pos, end - pos);
    pos = std::min(end + 1, data.size());
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream words(line);
    std::string keyword;
    words >> keyword;
    if (number == 1) {
      if (keyword != "ply") fail("does not start with 'ply'");
      continue;
    }
    if (keyword == "end_header") {
      if (!have_format) fail("ends without a format line");
      header.body_offset = pos;
      return header;
    }
    if (keyword == "comment" || keyword == "obj_info" || keyword.empty()) continue;
    if (keyword == "format") {
      std::string format;
      words >> format;
      if (format == "ascii") {
        header.format = Format::kAscii;
      } else if (format == "binary_little_endian") {
        header.format = Format::kLittleEndian;
      } else if (format == "binary_big_endian") {
        header.format = Format::kBigEndian;
      } else {
        fail("names the format '" + format +
             "' (ascii, binary_little_endian or binary_big_endian expected)");
      }
      have_format = true;
    } else if (keyword == "element") {
      Element element;
      std::string count;
      if (!(words >> element.name >> count)) fail("names no element and count");
      // A count the file cannot hold (or -1) made CGAL read at the end of the file forever.
      if (count.empty() || count.size() > 18 ||
          count.find_first_not_of("0123456789") != std::string::npos ||
          std::stoull(count) > data.size()) {
        fail("gives element " + element.name + " the count '" + count + "', not a number of " +
             "elements its " + std::to_string(data.size()) + " bytes can hold");
      }
      element.count = std::stoull(count);
      header.elements.push_back(element);
    } else if (keyword == "property") {
      if (header.elements.empty()) fail("declares a property before any element");
      Element& element = header.elements.back();
      Property property;
      std::string type;
      words >> type;
      if (type == "list") {
        std::string size_type, item_type;
        words >> size_type >> item_type >> property.name;
        property.size_type = find_type(size_type);
        property.type = find_type(item_type);
        if (!property.size_type || !property.size_type->integer) {
          fail("gives list " + property.name + " the count type '" + size_type +
               "' (an integer type expected)");
        }
        if (!property.type) fail("gives list " + property.name + " the type '" + item_type + "'");
        if (element.name == "face" &&
            (property.name == "vertex_indices" || property.name == "vertex_index") &&
            !property.type->integer) {
          fail("gives the face indices a type that is not an integer ('" + item_type + "')");
        }
      } else {
        words >> property.name;
        property.type = find_type(type);
        if (!property.type) fail("gives property " + property.name + " the type '" + type + "'");
      }
      if (property.name.empty()) fail("declares a property without a name");
      element.properties.push_back(property);
    } else {
      fail("has the unknown keyword '" + keyword + "'");
    }
  }
}

// Reads the body's values one at a time, in the header's types; every read is bounds-checked.
class BodyReader {
 public:
  BodyReader(const std::string& path, const std::string& data, const Header& header)
      : path_(path), data_(data), pos_(header.body_offset), format_(header.format) {}

  double value(const ScalarType& type) {
    return format_ == Format::kAscii ? ascii(type) : binary(type);
  }

  // A list's count: a whole number whose items the rest of the file can hold.
  std::uint64_t list_count(const ScalarType& size_type, const ScalarType& item_type) {
    const double count = value(size_type);
    const std::size_t left = data_.size() - pos_;
    const double most = format_ == Format::kAscii ? static_cast<double>(left) / 2 + 1
                                                  : static_cast<double>(left / item_type.bytes);
    if (!(count >= 0) || count > most) {
      fail("has a list of " + number_text(count) + " items, more than the rest of the file holds");
    }
    return static_cast<std::uint64_t>(count);
  }

  void skip(const ScalarType& type, std::uint64_t count) {
    if (format_ != Format::kAscii) {
      const std::uint64_t bytes = count * static_cast<std::uint64_t>(type.bytes);
      if (bytes > data_.size() - pos_) fail("ends early");
      pos_ += static_cast<std::size_t>(bytes);
      return;
    }
    for (std::uint64_t i = 0; i < count; ++i) value(type);
  }

  [[noreturn]] void fail(const std::string& why) const {
    throw InputError(path_ + ": the PLY body " + why + " (at byte " + std::to_string(pos_) + ")");
  }

 private:
  double ascii(const ScalarType& type) {
    while (pos_ < data_.size() && std::isspace(static_cast<unsigned char>(data_[pos_]))) ++pos_;
    if (pos_ >= data_.size()) fail("ends early");
    std::size_t end = pos_;  // the token ends at white space (or a NUL, where strtod stops)
    while (end < data_.size() && !std::isspace(static_cast<unsigned char>(data_[end])) &&
           data_[end] != '\0') {
      ++end;
    }
    const char* start = data_.c_str() + pos_;
    char* stop = nullptr;
    const double v = std::strtod(start, &stop);  // cannot cross white space
    if (stop != data_.c_str() + end || end == pos_) {
      fail("has '" + data_.substr(pos_, std::min<std::size_t>(end - pos_, 40)) + "' where a " +
           type.name + " is expected");
    }
    if (type.integer && v != std::floor(v)) {
      fail("has '" + data_.substr(pos_, std::min<std::size_t>(end - pos_, 40)) +
           "' where a whole number (" + type.name + ") is expected");
    }
    pos_ = end;
    return v;
  }

  double binary(const ScalarType& type) {
    if (static_cast<std::size_t>(type.bytes) > data_.size() - pos_) fail("ends early");
    unsigned char bytes[8];
    std::memcpy(bytes, data_.data() + pos_, type.bytes);
    pos_ += type.bytes;
    if (format_ == Format::kBigEndian) std::reverse(bytes, bytes + type.bytes);  // x86: little
    auto as = [&](auto v) {
      std::memcpy(&v, bytes, sizeof v);
      return static_cast<double>(v);
    };
    switch (type.bytes) {
      case 1:
        return type.is_signed ? as(std::int8_t{}) : as(std::uint8_t{});
      case 2:
        return type.is_signed ? as(std::int16_t{}) : as(std::uint16_t{});
      case 4:
        if (!type.integer) return as(float{});
        return type.is_signed ? as(std::int32_t{}) : as(std::uint32_t{});
      default:
        break;
    }
    return as(double{});
  }

  const std::string& path_;
  const std::string& data_;
  std::size_t pos_;
  Format format_;
};

bool is_face_list(const Element& element, const Property& property) {
  return element.name == "face" && property.size_type &&
         (property.name == "vertex_indices" || property.name == "vertex_index");
}

}  // namespace

PolygonSoup read_ply(const std::string& path) {
  std::string data;
  {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw IoError(path + ": cannot be opened for reading");
    data.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  const Header header = parse_header(path, data);

  const Element* vertex = nullptr;
  for (const Element& element : header.elements) {
    if (element.name == "vertex") vertex = &element;
  }
  if (!vertex) throw InputError(path + ": the PLY header declares no vertex element");
  int xyz[3] = {-1, -1, -1};
  for (std::size_t p = 0; p < vertex->properties.size(); ++p) {
    const Property& property = vertex->properties[p];
    for (int k = 0; k < 3; ++k) {
      if (property.name == std::string(1, static_cast<char>('x' + k)) && !property.size_type) {
        xyz[k] = static_cast<int>(p);
      }
    }
  }
  if (*std::min_element(xyz, xyz + 3) < 0) {
    throw InputError(path + ": the PLY vertex element lacks one of the properties x, y, z");
  }

  BodyReader body(path, data, header);
  PolygonSoup soup;
  for (const Element& element : header.elements) {
    if (element.properties.empty()) continue;  // nothing to read, whatever the count
    const bool is_vertex = &element == vertex;
    for (std::uint64_t i = 0; i < element.count; ++i) {
      for (std::size_t p = 0; p < element.properties.size(); ++p) {
        const Property& property = element.properties[p];
        if (!property.size_type) {
          const double v = body.value(*property.type);
          if (is_vertex) {
            for (int k = 0; k < 3; ++k) {
              if (xyz[k] == static_cast<int>(p)) soup.coordinates.push_back(v);
            }
          }
          continue;
        }
        const std::uint64_t count = body.list_count(*property.size_type, *property.type);
        if (!is_face_list(element, property)) {
          body.skip(*property.type, count);
          continue;
        }
        for (std::uint64_t k = 0; k < count; ++k)
          soup.corners.push_back(body.value(*property.type));
        soup.sizes.push_back(static_cast<std::size_t>(count));
      }
    }
  }

  return soup;
}

}  // namespace dcg::internal
