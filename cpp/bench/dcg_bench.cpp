// dcg_bench: times every stage of the engine (dcg::Extractor) on mesh files and, on closed
// manifold meshes, CGAL's mean curvature flow skeleton in the same process as the baseline.
//
//   dcg_bench [--repeat N] [--no-mcf] [--mcf-max-faces N] [--no-stability]
//             [--stability-seed N] [--skeleton-dir DIR] [--output FILE]
//             [--option NAME=VALUE]... [--repair auto|none] PATH...
//
// PATH is a mesh file (.obj .off .ply .stl) or a folder whose mesh files (not recursive) are
// run in name order. Output: JSON lines, one "meta" record, then one "mesh" record per file:
//   {"type":"mesh","mesh":"hand.obj","faces":9556,"stages":{"prepare":0.05,...},"total":0.2,
//    "mcf":{"status":"ok","seconds":0.34,...},"ratio":1.7,"error":null,...}
// "stages" holds whatever the Extractor timed, in the order it ran (new stages appear by
// themselves); "total" is the engine's own time for the run (the stages' sum, less the time stage
// 3 ran beside stages 1-2 on a second thread); "ratio" = MCF seconds / total. A mesh that fails
// gets its message in "error" and the run goes on. Progress goes to stderr.
// Quality, outside the timings: "engine" holds our skeleton's ends, joints, connections,
// cycles and inside % (samples along the skeleton inside the input by ray parity), "mcf" the
// same inside % for CGAL's skeleton, "stability" whether ends and joints stay the same when the
// mesh is rotated, scaled, shaken by 0.3% noise and remeshed with another seed (one more run,
// random draws seeded by --stability-seed and the file name, so the report is reproducible).
// --skeleton-dir writes both skeletons per mesh (<DIR>/<file name>.json, for the contact sheet).
// scripts/bench.py (`make bench`) runs this and writes out/bench/report.md.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <numeric>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "dcg/io.h"
#include "dcg/pipeline.h"
#include "dcg/surface_query.h"
#include "mcf_baseline.h"
#include "union_find.h"

#ifndef DCG_BENCH_BUILD_TYPE
#define DCG_BENCH_BUILD_TYPE "unknown"
#endif

namespace {

namespace fs = std::filesystem;

double now_seconds() {
  using Clock = std::chrono::steady_clock;
  return std::chrono::duration<double>(Clock::now().time_since_epoch()).count();
}

// --- a minimal JSON writer ------------------------------------------------------------------

std::string json_string(const std::string& s) {
  std::string out = "\"";
  for (unsigned char c : s) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (c < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", c);
          out += buf;
        } else {
          out += static_cast<char>(c);
        }
    }
  }
  return out + "\"";
}

std::string json_number(double v) {
  if (!std::isfinite(v)) return "null";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

// Builds one JSON object, fields in insertion order.
class JsonObject {
 public:
  JsonObject& raw(const std::string& key, const std::string& json) {
    text_ += (text_.empty() ? "" : ",") + json_string(key) + ":" + json;
    return *this;
  }
  JsonObject& str(const std::string& key, const std::string& value) {
    return raw(key, json_string(value));
  }
  JsonObject& num(const std::string& key, double value) { return raw(key, json_number(value)); }
  JsonObject& integer(const std::string& key, long long value) {
    return raw(key, std::to_string(value));
  }
  JsonObject& boolean(const std::string& key, bool value) {
    return raw(key, value ? "true" : "false");
  }
  JsonObject& null(const std::string& key) { return raw(key, "null"); }
  std::string dump() const { return "{" + text_ + "}"; }

 private:
  std::string text_;
};

// --- command line -----------------------------------------------------------------------------

struct Args {
  std::vector<std::string> paths;
  int repeat = 1;               // runs of our pipeline per mesh; the fastest total is reported
  bool mcf = true;              // run the CGAL baseline
  long long mcf_max_faces = 0;  // skip MCF above this many faces (0: no limit)
  int mcf_repeat = 1;           // MCF runs per mesh (while they total under kMcfRepeatSeconds)
  bool stability = true;        // one more run on a rotated, scaled, noisy, reseeded copy
  unsigned stability_seed = 1;  // with the file name, seeds the copy's random draws
  std::string skeleton_dir;     // write <dir>/<file name>.json with both skeletons ("": no)
  std::string output;           // JSON lines file ("" or "-": stdout)
  dcg::Options options;
};

void print_usage(std::ostream& os) {
  os << "usage: dcg_bench [--repeat N] [--no-mcf] [--mcf-max-faces N] [--mcf-repeat N]\n"
        "                 [--no-stability]\n"
        "                 [--stability-seed N] [--skeleton-dir DIR] [--output FILE]\n"
        "                 [--option NAME=VALUE]... [--repair auto|none] PATH...\n"
        "Times every stage of the DCG engine on each mesh (.obj .off .ply .stl) of the given\n"
        "files and folders, and CGAL's mean curvature flow skeleton on the closed manifold ones.\n"
        "Writes JSON lines (stdout by default).\n"
        "  --repeat N          runs of our pipeline per mesh, the fastest is kept (default 1)\n"
        "  --no-mcf            do not run the CGAL baseline\n"
        "  --mcf-max-faces N   skip the baseline on meshes with more than N faces (0: no limit)\n"
        "  --mcf-repeat N      runs of the baseline per mesh, while they take under 2 s in all;\n"
        "                      its median time is kept (default 1; MCF's own skeleton, and its\n"
        "                      time, change from run to run on many meshes)\n"
        "  --no-stability      skip the stability run (rotated, scaled, 0.3% noise, new seed)\n"
        "  --stability-seed N  seed of the stability run's draws, with the file name (default 1)\n"
        "  --skeleton-dir DIR  write DIR/<file name>.json: our skeleton and CGAL's\n"
        "  --output FILE       write the JSON lines to FILE\n"
        "  --option NAME=VALUE set an engine option (see README.md, Options)\n"
        "  --repair auto|none  the engine's repair option\n";
}

Args parse_args(int argc, char** argv) {
  Args args;
  auto value = [&](int& i) -> std::string {
    if (i + 1 >= argc) throw std::invalid_argument(std::string(argv[i]) + " needs a value");
    return argv[++i];
  };
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "-h" || a == "--help") {
      print_usage(std::cout);
      std::exit(0);
    } else if (a == "--repeat") {
      args.repeat = std::stoi(value(i));
      if (args.repeat < 1) throw std::invalid_argument("--repeat must be at least 1");
    } else if (a == "--no-mcf") {
      args.mcf = false;
    } else if (a == "--mcf-max-faces") {
      args.mcf_max_faces = std::stoll(value(i));
    } else if (a == "--mcf-repeat") {
      args.mcf_repeat = std::stoi(value(i));
      if (args.mcf_repeat < 1) throw std::invalid_argument("--mcf-repeat must be at least 1");
    } else if (a == "--no-stability") {
      args.stability = false;
    } else if (a == "--stability-seed") {
      args.stability_seed = static_cast<unsigned>(std::stoul(value(i)));
    } else if (a == "--skeleton-dir") {
      args.skeleton_dir = value(i);
    } else if (a == "--output" || a == "-o") {
      args.output = value(i);
    } else if (a == "--option") {
      const std::string kv = value(i);
      const auto eq = kv.find('=');
      if (eq == std::string::npos) throw std::invalid_argument("--option wants NAME=VALUE");
      dcg::set_numeric_option(args.options, kv.substr(0, eq), std::stod(kv.substr(eq + 1)));
    } else if (a == "--repair") {
      args.options.prepare.repair = dcg::parse_repair(value(i));
    } else if (!a.empty() && a[0] == '-' && a != "-") {
      throw std::invalid_argument("unknown flag " + a);
    } else {
      args.paths.push_back(a);
    }
  }
  if (args.paths.empty()) throw std::invalid_argument("no mesh file or folder given");
  return args;
}

bool is_mesh_file(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext == ".obj" || ext == ".off" || ext == ".ply" || ext == ".stl";
}

// Files as given; folders expanded to their mesh files in name order. A path that does not
// exist is kept, so that its row says so.
std::vector<fs::path> collect_meshes(const std::vector<std::string>& paths) {
  std::vector<fs::path> out;
  for (const auto& p : paths) {
    std::error_code ec;
    if (fs::is_directory(p, ec)) {
      std::vector<fs::path> files;
      for (const auto& entry : fs::directory_iterator(p, ec)) {
        if (entry.is_regular_file(ec) && is_mesh_file(entry.path())) files.push_back(entry.path());
      }
      std::sort(files.begin(), files.end());
      if (files.empty()) std::cerr << "dcg_bench: no mesh file in " << p << "\n";
      out.insert(out.end(), files.begin(), files.end());
    } else {
      out.emplace_back(p);
    }
  }
  return out;
}

// --- skeleton quality ---------------------------------------------------------------------------

// Bounding-box diagonal of the referenced vertices.
double diagonal(const dcg::Mesh& mesh) {
  if (mesh.V.rows() == 0) return 0;
  return (mesh.V.colwise().maxCoeff() - mesh.V.colwise().minCoeff()).norm();
}

// The samples of a skeleton inside the mesh by ray parity: every point, and along every segment
// a point each `spacing` (the segment's inner points, none on a segment shorter than
// `spacing`). Our skeleton (nodes and polyline points, polyline segments) and CGAL's (vertices,
// edges) are sampled alike. Each sample is tested once; the percentages are NAN without a
// surface query or samples.
struct InsideCounts {
  long points = 0, points_inside = 0;    // the points alone
  long samples = 0, samples_inside = 0;  // the points and the segments' samples
  double points_percent() const { return points ? 100.0 * points_inside / points : NAN; }
  double percent() const { return samples ? 100.0 * samples_inside / samples : NAN; }
};

InsideCounts inside_counts(const dcg::SurfaceQuery* surface, const dcg::Points& points,
                           const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>& segments,
                           double spacing) {
  InsideCounts c;
  if (!surface) return c;
  for (Eigen::Index i = 0; i < points.rows(); ++i, ++c.points)
    c.points_inside += surface->inside_by_parity(points.row(i).transpose());
  c.samples = c.points;
  c.samples_inside = c.points_inside;
  for (const auto& [a, b] : segments) {
    const int n = spacing > 0 ? static_cast<int>(std::ceil((b - a).norm() / spacing)) : 1;
    for (int k = 1; k < n; ++k, ++c.samples)
      c.samples_inside += surface->inside_by_parity(a + (b - a) * (double(k) / n));
  }
  return c;
}

struct Quality {
  int ends = 0, joints = 0, connections = 0, cycles = 0, components = 0, unlabelled_faces = 0;
  double inside_percent = NAN;         // samples along the skeleton, see inside_counts()
  double inside_points_percent = NAN;  // nodes and polyline points only
};

Quality quality(const dcg::SurfaceQuery* surface, double spacing, const dcg::Skeleton& s) {
  Quality q;
  const int n = static_cast<int>(s.positions.rows());
  dcg::internal::UnionFind components(n);
  for (Eigen::Index l = 0; l < s.links.rows(); ++l) components.unite(s.links(l, 0), s.links(l, 1));
  for (int i = 0; i < n; ++i) {
    q.components += components.find(i) == i;
    q.ends += s.kinds[i] == dcg::NodeKind::End;
    q.joints += s.kinds[i] == dcg::NodeKind::Joint;
    q.connections += s.kinds[i] == dcg::NodeKind::Connection;
  }
  q.cycles = static_cast<int>(s.links.rows()) - n + q.components;
  for (Eigen::Index f = 0; f < s.face_labels.size(); ++f)
    q.unlabelled_faces += s.face_labels[f] < 0;
  // The nodes and the polylines' inner points (their end points are nodes).
  Eigen::Index count = n;
  for (const auto& p : s.polylines) count += std::max<Eigen::Index>(p.rows() - 2, 0);
  dcg::Points points(count, 3);
  points.topRows(n) = s.positions;
  Eigen::Index row = n;
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> segments;
  for (const auto& p : s.polylines) {
    for (Eigen::Index i = 1; i + 1 < p.rows(); ++i) points.row(row++) = p.row(i);
    for (Eigen::Index i = 0; i + 1 < p.rows(); ++i)
      segments.emplace_back(p.row(i).transpose(), p.row(i + 1).transpose());
  }
  const InsideCounts inside = inside_counts(surface, points, segments, spacing);
  q.inside_points_percent = inside.points_percent();
  q.inside_percent = inside.percent();
  return q;
}

// --- stability: the same mesh rotated, scaled, moved and shaken ----------------------------------

// FNV-1a: a seed from the file name that does not depend on the platform or the run's order.
unsigned name_hash(const std::string& s) {
  std::uint32_t h = 2166136261u;
  for (unsigned char c : s) h = (h ^ c) * 16777619u;
  return h;
}

// x -> scale R x + t with R uniform on SO(3), scale 10^U(-2, 2), t within 10 diagonals, then
// every coordinate moved by U(-1, 1) 0.3% of the diagonal (tests/cpp/shapes.h does the same).
dcg::Mesh perturbed(const dcg::Mesh& mesh, std::mt19937& rng, double* scale_out = nullptr) {
  std::normal_distribution<double> g;
  Eigen::Quaterniond q(g(rng), g(rng), g(rng), g(rng));
  q.normalize();
  const Eigen::Matrix3d R = q.toRotationMatrix();
  const double scale = std::pow(10.0, std::uniform_real_distribution<double>(-2, 2)(rng));
  if (scale_out) *scale_out = scale;
  const double diag = diagonal(mesh);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Eigen::Vector3d t(10 * diag * u(rng), 10 * diag * u(rng), 10 * diag * u(rng));
  dcg::Mesh out = mesh;
  for (Eigen::Index i = 0; i < out.V.rows(); ++i) {
    out.V.row(i) = (scale * (R * mesh.V.row(i).transpose()) + scale * t).transpose();
    for (int k = 0; k < 3; ++k) out.V(i, k) += 0.003 * scale * diag * u(rng);
  }
  return out;
}

// --- the skeletons as JSON (--skeleton-dir) ------------------------------------------------------

std::string json_points(const dcg::Points& p) {
  std::string out = "[";
  for (Eigen::Index i = 0; i < p.rows(); ++i) {
    out += (i ? ",[" : "[") + json_number(p(i, 0)) + "," + json_number(p(i, 1)) + "," +
           json_number(p(i, 2)) + "]";
  }
  return out + "]";
}

std::string json_array(const std::vector<double>& values) {
  std::string out = "[";
  for (std::size_t i = 0; i < values.size(); ++i) out += (i ? "," : "") + json_number(values[i]);
  return out + "]";
}

// Runs of the baseline per mesh go on while they total under this (big meshes run once).
constexpr double kMcfRepeatSeconds = 2.0;

// The median of `seconds` (the mean of the middle two for an even count; NaN for none).
double median(std::vector<double> seconds) {
  if (seconds.empty()) return NAN;
  std::sort(seconds.begin(), seconds.end());
  const std::size_t n = seconds.size();
  return n % 2 ? seconds[n / 2] : 0.5 * (seconds[n / 2 - 1] + seconds[n / 2]);
}

std::string json_pairs(const dcg::Edges& e) {
  std::string out = "[";
  for (Eigen::Index i = 0; i < e.rows(); ++i)
    out += (i ? ",[" : "[") + std::to_string(e(i, 0)) + "," + std::to_string(e(i, 1)) + "]";
  return out + "]";
}

std::string skeleton_json(const dcg::Skeleton& s) {
  std::string kinds = "[", polylines = "[";
  for (size_t i = 0; i < s.kinds.size(); ++i)
    kinds += (i ? "," : "") + json_string(dcg::node_kind_name(s.kinds[i]));
  for (size_t i = 0; i < s.polylines.size(); ++i)
    polylines += (i ? "," : "") + json_points(s.polylines[i]);
  JsonObject o;
  o.str("method", s.method)
      .raw("positions", json_points(s.positions))
      .raw("kinds", kinds + "]")
      .raw("links", json_pairs(s.links))
      .raw("polylines", polylines + "]");
  return o.dump();
}

// --- one mesh -----------------------------------------------------------------------------------

std::string bench_mesh(const fs::path& path, const Args& args) {
  JsonObject row;
  row.str("type", "mesh").str("mesh", path.filename().string()).str("path", path.string());
  std::string error;
  dcg::Mesh mesh;
  bool loaded = false;
  double total = NAN;
  std::unique_ptr<dcg::SurfaceQuery> surface;  // the input's surface, for the inside tests
  double spacing = 0;                          // of the inside samples: 0.5% of the diagonal
  dcg::Skeleton ours;                          // the skeleton of the fastest run
  Quality best_quality;
  bool have_ours = false;
  try {
    const double t0 = now_seconds();
    mesh = dcg::read_mesh(path.string());
    row.num("load_seconds", now_seconds() - t0);
    loaded = true;
    row.integer("vertices", mesh.V.rows()).integer("faces", mesh.F.rows());
    spacing = 0.005 * diagonal(mesh);
    try {
      surface = std::make_unique<dcg::SurfaceQuery>(mesh);
    } catch (const std::exception&) {
      surface.reset();  // inside % is then null
    }
    std::cerr << "dcg_bench: " << path.filename().string() << " (" << mesh.F.rows()
              << " faces): ours" << std::flush;

    // Our pipeline, every stage, `repeat` times on fresh extractors; keep the fastest.
    std::vector<std::pair<std::string, double>> best;
    std::vector<double> totals;
    double best_wall = NAN;
    JsonObject info;
    for (int r = 0; r < args.repeat; ++r) {
      const double t1 = now_seconds();
      dcg::Extractor extractor(mesh.V, mesh.F, args.options);
      const dcg::Skeleton& skeleton = extractor.skeleton();
      const double wall = now_seconds() - t1;
      std::vector<std::pair<std::string, double>> stages;
      double run_total = NAN, sum = 0;
      for (const auto& [name, seconds] : skeleton.timings) {
        if (name == "total") {
          run_total = seconds;
        } else {
          stages.emplace_back(name, seconds);
          sum += seconds;
        }
      }
      if (!std::isfinite(run_total)) run_total = sum;
      totals.push_back(run_total);
      if (!std::isfinite(total) || run_total < total) {
        total = run_total;
        best = stages;
        best_wall = wall;
        const dcg::PreparedMesh& pm = extractor.prepare();  // kept: costs nothing now
        info = JsonObject();
        info.str("method", skeleton.method)
            .integer("working_faces", pm.working.F.rows())
            .boolean("repaired", pm.repaired)
            .boolean("remeshed", pm.remeshed)
            .integer("genus", pm.genus)
            .integer("nodes", skeleton.positions.rows())
            .integer("links", skeleton.links.rows());
        ours = skeleton;
        have_ours = true;
      }
    }
    if (have_ours) {
      // Quality of the fastest run's skeleton (outside the timing; every run gives the same):
      // kinds, cycles, components, the share of samples along the skeleton inside the input
      // (ray parity; also of the nodes and polyline points alone), unlabelled input faces.
      best_quality = quality(surface.get(), spacing, ours);
      info.integer("ends", best_quality.ends)
          .integer("joints", best_quality.joints)
          .integer("connections", best_quality.connections)
          .integer("cycles", best_quality.cycles)
          .integer("components", best_quality.components)
          .num("inside_percent", best_quality.inside_percent)
          .num("inside_points_percent", best_quality.inside_points_percent)
          .integer("unlabelled_faces", best_quality.unlabelled_faces);
    }
    JsonObject stages;
    for (const auto& [name, seconds] : best) stages.num(name, seconds);
    std::string totals_json = "[";
    for (size_t i = 0; i < totals.size(); ++i)
      totals_json += (i ? "," : "") + json_number(totals[i]);
    totals_json += "]";
    row.raw("stages", stages.dump())
        .num("total", total)
        .num("wall", best_wall)
        .raw("totals", totals_json)
        .raw("engine", info.dump());
    std::cerr << " " << json_number(total) << " s" << std::flush;
  } catch (const std::exception& e) {
    error = e.what();
  } catch (...) {
    error = "unknown exception";
  }

  // Stability (not timed as ours): one more run on a rotated, scaled, moved, noisy copy with
  // another seed; are the ends and joints the same as above?
  if (have_ours && args.stability) {
    JsonObject st;
    try {
      std::cerr << ", stability" << std::flush;
      std::mt19937 rng(args.stability_seed ^ name_hash(path.filename().string()));
      double scale = 1;
      const dcg::Mesh moved = perturbed(mesh, rng, &scale);
      dcg::Options options = args.options;
      options.seed = args.options.seed + 1;
      const double t1 = now_seconds();
      dcg::Extractor extractor(moved.V, moved.F, options);
      const dcg::Skeleton& skeleton = extractor.skeleton();
      const Quality q = quality(nullptr, 0, skeleton);
      st.str("status", "ok")
          .str("method", skeleton.method)
          .num("seconds", now_seconds() - t1)
          .integer("seed", options.seed)
          .num("scale", scale)
          .integer("ends", q.ends)
          .integer("joints", q.joints)
          .integer("cycles", q.cycles)
          .boolean("same_ends", q.ends == best_quality.ends)
          .boolean("same_joints", q.joints == best_quality.joints)
          .boolean("stable", q.ends == best_quality.ends && q.joints == best_quality.joints);
      std::cerr << (q.ends == best_quality.ends && q.joints == best_quality.joints ? " same"
                                                                                   : " differs");
    } catch (const std::exception& e) {
      st = JsonObject();
      st.str("status", "failed").str("note", e.what()).null("stable");
      std::cerr << " failed";
    }
    row.raw("stability", st.dump());
  } else {
    row.null("stability");
  }

  // The baseline, on the same triangles, when they loaded (even if our engine failed).
  double mcf_seconds = NAN;
  dcg::bench::McfResult mcf;                      // the first run: its skeleton is the one reported
  std::vector<double> run_seconds, run_vertices;  // every successful run's time and skeleton size
  if (loaded) {
    bool ran = false;
    if (!args.mcf) {
      mcf.note = "disabled (--no-mcf)";
    } else if (args.mcf_max_faces > 0 && mesh.F.rows() > args.mcf_max_faces) {
      mcf.note = "more than " + std::to_string(args.mcf_max_faces) + " faces (--mcf-max-faces)";
    } else {
      std::cerr << ", MCF" << std::flush;
      mcf = dcg::bench::run_mcf_skeleton(mesh.V, mesh.F);
      ran = true;
      for (dcg::bench::McfResult run = mcf; run.status == dcg::bench::McfResult::Status::Ok;) {
        run_seconds.push_back(run.seconds);
        run_vertices.push_back(run.skeleton_vertices);
        if (static_cast<int>(run_seconds.size()) >= args.mcf_repeat ||
            std::accumulate(run_seconds.begin(), run_seconds.end(), 0.0) >= kMcfRepeatSeconds)
          break;
        run = dcg::bench::run_mcf_skeleton(mesh.V, mesh.F);
      }
    }
    JsonObject m;
    m.str("status", dcg::bench::status_name(mcf.status));
    if (mcf.status == dcg::bench::McfResult::Status::Ok) {
      mcf_seconds = median(run_seconds);
      // Its inside %, sampled like ours: vertices, and along every edge.
      std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> segments;
      for (Eigen::Index e = 0; e < mcf.edges.rows(); ++e) {
        segments.emplace_back(mcf.points.row(mcf.edges(e, 0)).transpose(),
                              mcf.points.row(mcf.edges(e, 1)).transpose());
      }
      const InsideCounts inside = inside_counts(surface.get(), mcf.points, segments, spacing);
      m.num("seconds", mcf_seconds)
          .raw("runs_seconds", json_array(run_seconds))
          .raw("runs_skeleton_vertices", json_array(run_vertices))
          .num("build_seconds", mcf.build_seconds)
          .integer("mesh_vertices", mcf.mesh_vertices)
          .boolean("welded", mcf.welded)
          .integer("skeleton_vertices", mcf.skeleton_vertices)
          .integer("skeleton_edges", mcf.skeleton_edges)
          .num("inside_percent", inside.percent())
          .num("inside_points_percent", inside.points_percent());
      std::cerr << " " << json_number(mcf_seconds) << " s";
    } else {
      m.null("seconds");
      std::cerr << (ran ? " " : ", MCF ") << mcf.note;
    }
    m.str("note", mcf.note);
    row.raw("mcf", m.dump());
  } else {
    row.null("mcf");
  }
  row.num("ratio", std::isfinite(total) && total > 0 ? mcf_seconds / total : NAN);

  // Both skeletons for the contact sheet.
  if (loaded && !args.skeleton_dir.empty()) {
    std::error_code ec;
    fs::create_directories(args.skeleton_dir, ec);
    const fs::path file = fs::path(args.skeleton_dir) / (path.filename().string() + ".json");
    std::ofstream out(file);
    JsonObject o;
    o.str("mesh", path.filename().string()).str("path", path.string());
    if (have_ours) {
      o.raw("ours", skeleton_json(ours));
    } else {
      o.null("ours");
    }
    if (mcf.status == dcg::bench::McfResult::Status::Ok) {
      JsonObject m;
      m.raw("points", json_points(mcf.points)).raw("edges", json_pairs(mcf.edges));
      o.raw("mcf", m.dump());
    } else {
      o.null("mcf");
    }
    out << o.dump() << "\n";
    if (!out) std::cerr << " (cannot write " << file.string() << ")";
    row.str("skeleton_file", file.string());
  }

  if (error.empty()) {
    row.null("error");
  } else {
    row.str("error", error);
    std::cerr << (loaded ? " " : "dcg_bench: " + path.filename().string() + ": ") << "ERROR "
              << error;
  }
  std::cerr << "\n";
  return row.dump();
}

}  // namespace

int main(int argc, char** argv) {
  Args args;
  try {
    args = parse_args(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "dcg_bench: " << e.what() << "\n";
    print_usage(std::cerr);
    return 2;
  }
  std::ofstream file;
  if (!args.output.empty() && args.output != "-") {
    file.open(args.output);
    if (!file) {
      std::cerr << "dcg_bench: cannot write " << args.output << "\n";
      return 2;
    }
  }
  std::ostream& out = file.is_open() ? static_cast<std::ostream&>(file) : std::cout;

  JsonObject meta;
  meta.str("type", "meta")
      .str("build_type", DCG_BENCH_BUILD_TYPE)
      .str("cgal", dcg::bench::cgal_version())
      .integer("repeat", args.repeat)
      .integer("mcf_repeat", args.mcf_repeat)
      .num("mcf_repeat_seconds", kMcfRepeatSeconds)
      .boolean("mcf", args.mcf)
      .integer("mcf_max_faces", args.mcf_max_faces)
      .str("repair", dcg::repair_name(args.options.prepare.repair))
      .boolean("stability", args.stability)
      .integer("stability_seed", args.stability_seed);
  JsonObject options;
  for (const auto& spec : dcg::option_specs()) {
    if (spec.kind == dcg::OptionSpec::Kind::Choice) continue;  // repair: above
    options.num(spec.name, dcg::get_numeric_option(args.options, spec.name));
  }
  meta.raw("options", options.dump());
  out << meta.dump() << std::endl;

  for (const auto& path : collect_meshes(args.paths)) out << bench_mesh(path, args) << std::endl;
  return 0;
}
