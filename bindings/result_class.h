// The engine's result structs as Python classes, each field bound once (ResultClass::field) and
// nowhere else: the struct in cpp/include/dcg is its documentation, the Python package adds no
// second spelling. Fields cross as the Python API promises:
//   double arrays (Points, VectorXd, ...)  numpy float64 views, read-only, that keep the result
//                                          alive (no copy)
//   int index arrays, std::vector<int>     numpy int64 (a copy: the API's index type)
//   std::vector<char> flags                numpy bool
//   std::vector<NodeKind>                  numpy str ("end", "joint", "connection")
//   timings (stage, seconds) pairs         dict, in the order they ran
//   MeshReport                             dict (with closed_manifold)
//   peaks of a ProngHierarchy              dict of #K arrays (vertices, values, valleys, ...)
//   other structs bound here               the bound object, kept alive by its owner
//   scalars, strings, lists of arrays      as pybind11 casts them (lists of views)
#pragma once

#include <functional>
#include <initializer_list>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "common.h"
#include "dcg/prongs.h"
#include "dcg/skeleton.h"

namespace dcg {
struct MeshReport;
}

namespace dcg_py {

using Timings = std::vector<std::pair<std::string, double>>;

/// Stage 3 as Python sees it (dcg.Prongs): the prongs at one tau and, for Extractor.prongs()
/// without tau, the stage-3 features they come from (owned by the extractor, which the Python
/// object keeps alive); null after re-thresholding.
struct ProngsView : dcg::Prongs {
  const dcg::ProngFeatures* features = nullptr;
};

template <typename Scalar, int R, int C, int O, int MR, int MC>
py::object to_python(const Eigen::Matrix<Scalar, R, C, O, MR, MC>& a, py::handle owner) {
  if constexpr (std::is_integral_v<Scalar>) {
    return py::cast(to_int64(a));
  } else {
    return py::cast(a, py::return_value_policy::reference_internal, owner);
  }
}
py::object to_python(const std::vector<int>& values, py::handle owner);
py::object to_python(const std::vector<char>& flags, py::handle owner);
py::object to_python(const std::vector<dcg::NodeKind>& kinds, py::handle owner);
py::object to_python(const Timings& timings, py::handle owner);
py::object to_python(const dcg::MeshReport& report, py::handle owner);
py::object to_python(const std::vector<dcg::Peak>& peaks, py::handle owner);
/// Anything else: bound structs by reference (kept alive by `owner`), values by value.
template <typename T>
py::object to_python(const T& value, py::handle owner) {
  return py::cast(value, py::return_value_policy::reference_internal, owner);
}

namespace fields {
template <typename T>
const T* address(const T& value) {
  return &value;
}
template <typename T>
const T* address(const T* pointer) {
  return pointer;
}

template <typename T>
const T* follow(const T* object) {
  return object;
}
/// The member (data member or accessor returning a reference) at the end of `path`, starting
/// at `object`; null when a pointer on the way is null.
template <typename T, typename Member, typename... Rest>
auto follow(const T* object, Member member, Rest... rest) {
  using Step = decltype(std::invoke(member, *object));
  static_assert(std::is_reference_v<Step>, "a field is a member, or an accessor returning one");
  using Next = std::decay_t<decltype(*address(std::declval<Step>()))>;
  const Next* next = object ? address(std::invoke(member, *object)) : nullptr;
  return follow(next, rest...);
}
}  // namespace fields

/// py::class_ of a read-only engine result.
template <typename T>
class ResultClass : public py::class_<T> {
 public:
  using py::class_<T>::class_;

  /// Binds the member at the end of `path` (a member of T, or of a member of T, ...) as the
  /// read-only property `name`; None when a pointer on the way is null.
  template <typename... Path>
  ResultClass& field(const char* name, Path... path) {
    this->def_property_readonly(name, [path...](py::handle self) -> py::object {
      const auto* value = fields::follow(&self.cast<const T&>(), path...);
      if (!value) return py::none();
      return to_python(*value, self);
    });
    return *this;
  }

  /// Binds each int member of `members` as a field, and all of them as the dict `name` (the
  /// counts a result reports of its rules).
  ResultClass& counts(const char* name,
                      std::initializer_list<std::pair<const char*, int T::*>> members) {
    auto all = std::make_shared<std::vector<std::pair<const char*, int T::*>>>(members);
    for (const auto& [field_name, member] : *all) field(field_name, member);
    this->def_property_readonly(name, [all](const T& result) {
      py::dict d;
      for (const auto& [field_name, member] : *all) d[field_name] = result.*member;
      return d;
    });
    return *this;
  }
};

}  // namespace dcg_py
