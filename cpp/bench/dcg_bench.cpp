// dcg_bench: times every stage of the engine (dcg::Extractor) on mesh files and, on closed
// manifold meshes, CGAL's mean curvature flow skeleton in the same process as the baseline.
//
//   dcg_bench [--repeat N] [--no-mcf] [--mcf-max-faces N] [--output FILE]
//             [--option NAME=VALUE]... [--repair auto|none] PATH...
//
// PATH is a mesh file (.obj .off .ply .stl) or a folder whose mesh files (not recursive) are
// run in name order. Output: JSON lines, one "meta" record, then one "mesh" record per file:
//   {"type":"mesh","mesh":"hand.obj","faces":9556,"stages":{"prepare":0.05,...},"total":0.2,
//    "mcf":{"status":"ok","seconds":0.34,...},"ratio":1.7,"error":null,...}
// "stages" holds whatever the Extractor timed, in the order it ran (new stages appear by
// themselves); "total" is the engine's own sum; "ratio" = MCF seconds / total. A mesh that fails
// gets its message in "error" and the run goes on. Progress goes to stderr.
// scripts/bench.py (`make bench`) runs this and writes out/bench/report.md.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "dcg/io.h"
#include "dcg/pipeline.h"
#include "dcg/surface_query.h"
#include "mcf_baseline.h"

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
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\r': out += "\\r"; break;
      case '\t': out += "\\t"; break;
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
  int repeat = 1;              // runs of our pipeline per mesh; the fastest total is reported
  bool mcf = true;             // run the CGAL baseline
  long long mcf_max_faces = 0;  // skip MCF above this many faces (0: no limit)
  std::string output;          // JSON lines file ("" or "-": stdout)
  dcg::Options options;
};

void print_usage(std::ostream& os) {
  os << "usage: dcg_bench [--repeat N] [--no-mcf] [--mcf-max-faces N] [--output FILE]\n"
        "                 [--option NAME=VALUE]... [--repair auto|none] PATH...\n"
        "Times every stage of the DCG engine on each mesh (.obj .off .ply .stl) of the given\n"
        "files and folders, and CGAL's mean curvature flow skeleton on the closed manifold ones.\n"
        "Writes JSON lines (stdout by default).\n"
        "  --repeat N          runs of our pipeline per mesh, the fastest is kept (default 1)\n"
        "  --no-mcf            do not run the CGAL baseline\n"
        "  --mcf-max-faces N   skip the baseline on meshes with more than N faces (0: no limit)\n"
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
    } else if (a == "--output" || a == "-o") {
      args.output = value(i);
    } else if (a == "--option") {
      const std::string kv = value(i);
      const auto eq = kv.find('=');
      if (eq == std::string::npos) throw std::invalid_argument("--option wants NAME=VALUE");
      dcg::set_numeric_option(args.options, kv.substr(0, eq), std::stod(kv.substr(eq + 1)));
    } else if (a == "--repair") {
      args.options.repair = dcg::parse_repair(value(i));
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

struct Quality {
  int ends = 0, joints = 0, connections = 0, cycles = 0, components = 0, unlabelled_faces = 0;
  double inside_percent = 100;
};

Quality quality(const dcg::Mesh& mesh, const dcg::Skeleton& s) {
  Quality q;
  const int n = static_cast<int>(s.positions.rows());
  std::vector<int> parent(n);
  for (int i = 0; i < n; ++i) parent[i] = i;
  auto find = [&](int x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  for (Eigen::Index l = 0; l < s.links.rows(); ++l) parent[find(s.links(l, 0))] = find(s.links(l, 1));
  for (int i = 0; i < n; ++i) {
    q.components += find(i) == i;
    q.ends += s.kinds[i] == dcg::NodeKind::End;
    q.joints += s.kinds[i] == dcg::NodeKind::Joint;
    q.connections += s.kinds[i] == dcg::NodeKind::Connection;
  }
  q.cycles = static_cast<int>(s.links.rows()) - n + q.components;
  for (Eigen::Index f = 0; f < s.face_labels.size(); ++f) q.unlabelled_faces += s.face_labels[f] < 0;
  try {
    const dcg::SurfaceQuery surface(mesh);
    int inside = 0, total = 0;
    for (int i = 0; i < n; ++i, ++total) inside += surface.inside_by_parity(s.positions.row(i).transpose());
    for (const auto& p : s.polylines) {
      for (Eigen::Index i = 1; i + 1 < p.rows(); ++i, ++total) inside += surface.inside_by_parity(p.row(i).transpose());
    }
    q.inside_percent = total ? 100.0 * inside / total : 100.0;
  } catch (const std::exception&) {
    q.inside_percent = NAN;
  }
  return q;
}

// --- one mesh -----------------------------------------------------------------------------------

std::string bench_mesh(const fs::path& path, const Args& args) {
  JsonObject row;
  row.str("type", "mesh").str("mesh", path.filename().string()).str("path", path.string());
  std::string error;
  dcg::Mesh mesh;
  bool loaded = false;
  double total = NAN;
  try {
    const double t0 = now_seconds();
    mesh = dcg::read_mesh(path.string());
    row.num("load_seconds", now_seconds() - t0);
    loaded = true;
    row.integer("vertices", mesh.V.rows()).integer("faces", mesh.F.rows());
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
        // Quality of the skeleton (outside the timing): kinds, cycles, components, the share
        // of nodes and polyline points inside the input (ray parity), unlabelled input faces.
        const Quality q = quality(mesh, skeleton);
        info.integer("ends", q.ends)
            .integer("joints", q.joints)
            .integer("connections", q.connections)
            .integer("cycles", q.cycles)
            .integer("components", q.components)
            .num("inside_percent", q.inside_percent)
            .integer("unlabelled_faces", q.unlabelled_faces);
      }
    }
    JsonObject stages;
    for (const auto& [name, seconds] : best) stages.num(name, seconds);
    std::string totals_json = "[";
    for (size_t i = 0; i < totals.size(); ++i) totals_json += (i ? "," : "") + json_number(totals[i]);
    totals_json += "]";
    row.raw("stages", stages.dump()).num("total", total).num("wall", best_wall)
        .raw("totals", totals_json).raw("engine", info.dump());
    std::cerr << " " << json_number(total) << " s" << std::flush;
  } catch (const std::exception& e) {
    error = e.what();
  } catch (...) {
    error = "unknown exception";
  }

  // The baseline, on the same triangles, when they loaded (even if our engine failed).
  double mcf_seconds = NAN;
  if (loaded) {
    dcg::bench::McfResult mcf;
    bool ran = false;
    if (!args.mcf) {
      mcf.note = "disabled (--no-mcf)";
    } else if (args.mcf_max_faces > 0 && mesh.F.rows() > args.mcf_max_faces) {
      mcf.note = "more than " + std::to_string(args.mcf_max_faces) + " faces (--mcf-max-faces)";
    } else {
      std::cerr << ", MCF" << std::flush;
      mcf = dcg::bench::run_mcf_skeleton(mesh.V, mesh.F);
      ran = true;
    }
    JsonObject m;
    m.str("status", dcg::bench::status_name(mcf.status));
    if (mcf.status == dcg::bench::McfResult::Status::Ok) {
      mcf_seconds = mcf.seconds;
      m.num("seconds", mcf.seconds)
          .num("build_seconds", mcf.build_seconds)
          .integer("mesh_vertices", mcf.mesh_vertices)
          .boolean("welded", mcf.welded)
          .integer("skeleton_vertices", mcf.skeleton_vertices)
          .integer("skeleton_edges", mcf.skeleton_edges);
      std::cerr << " " << json_number(mcf.seconds) << " s";
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
      .boolean("mcf", args.mcf)
      .integer("mcf_max_faces", args.mcf_max_faces)
      .str("repair", dcg::repair_name(args.options.repair));
  JsonObject options;
  for (const auto& spec : dcg::numeric_option_specs()) {
    options.num(spec.name, dcg::get_numeric_option(args.options, spec.name));
  }
  meta.raw("options", options.dump());
  out << meta.dump() << std::endl;

  for (const auto& path : collect_meshes(args.paths)) out << bench_mesh(path, args) << std::endl;
  return 0;
}
