// Plain data types shared by every stage. Row-major so that numpy arrays cross without copies.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>  // cross products, used by most stages

namespace dcg {

/// The default seed of every randomized step (Options::seed and the stages' own seed fields).
inline constexpr unsigned kDefaultSeed = 0;

/// #V by 3 vertex positions (or any list of 3D points).
using Vertices = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
using Points = Vertices;
/// #F by 3 triangle indices into a Vertices matrix.
using Faces = Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>;
/// #E by 2 index pairs (graph edges, links).
using Edges = Eigen::Matrix<int, Eigen::Dynamic, 2, Eigen::RowMajor>;

/// A triangle mesh: V #V by 3, F #F by 3 indices into V.
struct Mesh {
  Vertices V;
  Faces F;
};

/// Balls inside the shape: centers #B by 3, radii #B (distance from the center to the surface).
struct Balls {
  Points centers;
  Eigen::VectorXd radii;
};

}  // namespace dcg
