// The option table (dcg/options.h): each public option's name, description, range and unit,
// and where it lives in Options. Defaults are not here: they are the stage structs'.
#include "dcg/options.h"

#include <cmath>
#include <functional>

#include "dcg/errors.h"

namespace dcg {
namespace {

using Kind = OptionSpec::Kind;

// How to read and write one option of an Options as a number.
struct Access {
  std::function<double(const Options&)> get;
  std::function<void(Options&, double)> set;
};

// A field of a stage's struct (Owner is the stage struct or one of its bases).
template <class Stage, class Owner, class T>
Access member(Stage Options::* stage, T Owner::* field) {
  return {[=](const Options& o) { return static_cast<double>((o.*stage).*field); },
          [=](Options& o, double v) { (o.*stage).*field = static_cast<T>(v); }};
}

struct OptionEntry {
  OptionSpec spec;
  Access access;  // numbers only (repair is read and written by name)
};

OptionSpec number(const char* name, const char* stage, Kind kind, double minimum, double maximum,
                  const char* description, const char* unit = "") {
  return {name, description, stage, kind, minimum, maximum, {}, unit};
}

constexpr const char* kLength = "normalized length";

const std::vector<OptionEntry>& option_table() {
  static const std::vector<OptionEntry> table = {
      {{"repair",
        "What to do with input that is not one closed manifold: 'auto' unites its parts when "
        "each is a closed solid, else wraps it into a closed proxy (CGAL alpha wrapping), "
        "'none' raises an error naming the problem",
        "prepare",
        Kind::Choice,
        0,
        0,
        {"auto", "none"},
        ""},
       {}},
      {number("target_faces", "prepare", Kind::Int, 0, 2e6,
              "Triangles of the uniform working mesh after remeshing (0: keep the input)"),
       member(&Options::prepare, &PrepareOptions::target_faces)},
      {number("upsample", "prepare", Kind::Int, 0, 1,
              "1: remesh inputs smaller than target_faces / 2.5 up to target_faces (slower); "
              "0: use them as they are (with at most one sample per two faces)"),
       member(&Options::prepare, &PrepareOptions::upsample)},
      {number("samples", "voronoi_balls", Kind::Int, 100, 1e6,
              "Surface samples whose Voronoi vertices give the candidate balls"),
       member(&Options::voronoi, &VoronoiBallsOptions::samples)},
      {number("min_gap", "domain_balls", Kind::Float, 0, 0.5, "Gap kept between domain balls",
              kLength),
       member(&Options::domain, &DomainBallsOptions::min_gap)},
      {number("min_radius", "domain_balls", Kind::Float, 0, 0.5, "Smallest domain ball kept",
              kLength),
       member(&Options::domain, &DomainBallsOptions::min_radius)},
      {number("tau", "prongs", Kind::Float, 0.01, 1.0,
              "Prong smoothness ratio: a bump is a prong when valley / peak < tau"),
       member(&Options::prongs, &ProngOptions::tau)},
      {number("geodesic_sources", "prongs", Kind::Int, 0, 1e5,
              "Sources of the sampled geodesic scale function (0: every vertex, exact)"),
       member(&Options::prongs, &ProngOptions::geodesic_sources)},
      {number("rays", "force_field", Kind::Int, 6, 4096,
              "Rays cast per point for the repulsive force field"),
       member(&Options::field, &ForceFieldOptions::rays)},
      {number("force_exponent", "force_field", Kind::Float, 0.5, 4,
              "Exponent n of the force field F(p) = -1/K sum u_k / r_k^n"),
       member(&Options::field, &ForceFieldOptions::force_exponent)},
      {number("shrink_step", "connection_points", Kind::Float, 0.001, 1,
              "Initial step factor alpha when shrinking domain points along the field"),
       member(&Options::connection, &ConnectionPointsOptions::shrink_step)},
      {number("snake_iterations", "remap", Kind::Int, 0, 10000,
              "Iterations of the snake that re-maps each link"),
       member(&Options::remap, &RemapOptions::snake_iterations)},
      {number("max_influences", "weights", Kind::Int, 1, 64,
              "Most bones weighting one vertex (the strongest kept, then renormalized)"),
       member(&Options::weights, &WeightsOptions::max_influences)},
      {number("heat", "weights", Kind::Float, 1e-6, 1e6,
              "c of the heat H = c / d^2: larger binds vertices more rigidly to their nearest "
              "bone"),
       member(&Options::weights, &WeightsOptions::heat)},
      {number("min_weight", "weights", Kind::Float, 0, 0.99,
              "Weights below this fade out, to 0 at half of it (as Blender's bone heat)"),
       member(&Options::weights, &WeightsOptions::min_weight)},
      {number("bone_reach", "weights", Kind::Int, 0, 64,
              "A vertex's other bones lie within this many links of its strongest one (0: any), "
              "unless they weigh far_weight"),
       member(&Options::weights, &WeightsOptions::bone_reach)},
      {number("far_weight", "weights", Kind::Float, 0, 1,
              "Bones beyond bone_reach keep their weight from this weight up"),
       member(&Options::weights, &WeightsOptions::far_weight)},
      {number("tie_tolerance", "weights", Kind::Float, 0, 1,
              "Bones within this relative distance of the nearest visible one share its heat"),
       member(&Options::weights, &WeightsOptions::tie_tolerance)},
      {number("seed", "all", Kind::Int, 0, 4294967295.0,
              "Seed of every randomized step (same seed, same skeleton)"),
       {[](const Options& o) { return static_cast<double>(o.seed); },
        [](Options& o, double v) { o.seed = static_cast<unsigned>(v); }}},
  };
  return table;
}

const OptionEntry& find_entry(const std::string& name) {
  for (const auto& entry : option_table()) {
    if (entry.spec.name == name) return entry;
  }
  throw InputError("unknown option '" + name + "'");
}

const OptionEntry& numeric_entry(const std::string& name) {
  const OptionEntry& entry = find_entry(name);
  if (entry.spec.kind == Kind::Choice) throw InputError("option " + name + " is not a number");
  return entry;
}

std::string format_number(double v) {
  std::string s = std::to_string(v);
  s.erase(s.find_last_not_of('0') + 1);
  if (!s.empty() && s.back() == '.') s.pop_back();
  return s;
}

}  // namespace

const std::vector<OptionSpec>& option_specs() {
  static const std::vector<OptionSpec> specs = [] {
    std::vector<OptionSpec> out;
    for (const auto& entry : option_table()) out.push_back(entry.spec);
    return out;
  }();
  return specs;
}

const OptionSpec& option_spec(const std::string& name) { return find_entry(name).spec; }

void check_option(const std::string& name, double value) {
  const OptionSpec& spec = numeric_entry(name).spec;
  if (!std::isfinite(value) || value < spec.minimum || value > spec.maximum) {
    throw InputError("option " + spec.name + " = " + format_number(value) + " is out of range [" +
                     format_number(spec.minimum) + ", " + format_number(spec.maximum) + "]");
  }
  if (spec.kind == Kind::Int && value != std::floor(value)) {
    throw InputError("option " + spec.name + " must be a whole number, got " +
                     format_number(value));
  }
}

double get_numeric_option(const Options& options, const std::string& name) {
  return numeric_entry(name).access.get(options);
}

void set_numeric_option(Options& options, const std::string& name, double value) {
  check_option(name, value);
  numeric_entry(name).access.set(options, value);
}

std::string get_choice_option(const Options& options, const std::string& name) {
  if (name != "repair") throw InputError("option " + name + " is not a choice");
  return repair_name(options.prepare.repair);
}

void set_choice_option(Options& options, const std::string& name, const std::string& value) {
  if (name != "repair") throw InputError("option " + name + " is not a choice");
  options.prepare.repair = parse_repair(value);
}

PrepareOptions Options::prepare_options() const {
  PrepareOptions out = prepare;
  out.seed = seed;
  return out;
}

void Options::validate() const {
  for (const auto& entry : option_table()) {
    if (entry.spec.kind != Kind::Choice) check_option(entry.spec.name, entry.access.get(*this));
  }
}

Repair parse_repair(const std::string& text) {
  if (text == "auto") return Repair::Auto;
  if (text == "none") return Repair::None;
  throw InputError("option repair must be 'auto' or 'none', got '" + text + "'");
}

const char* repair_name(Repair repair) { return repair == Repair::Auto ? "auto" : "none"; }

}  // namespace dcg
