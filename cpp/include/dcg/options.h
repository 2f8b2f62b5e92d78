// Every option of the engine: the stages' own option structs composed into one Options, and the
// one table that gives each public option its name, description, range and unit. Defaults live
// in the stage structs (one place each); ranges live in the table (one place each). Python's
// keyword arguments, both CLIs and the add-on's properties are generated from the table.
#pragma once

#include <string>
#include <vector>

#include "dcg/connection_points.h"
#include "dcg/domain_balls.h"
#include "dcg/force_field.h"
#include "dcg/prepare.h"
#include "dcg/prongs.h"
#include "dcg/remap.h"
#include "dcg/types.h"
#include "dcg/voronoi_balls.h"
#include "dcg/weights.h"

namespace dcg {

/// Every option of the pipeline (stages 0-8) and of the weights (stage 9), with ALGORITHM.md's
/// defaults. Lengths are in normalized units (the input's bounding-box diagonal is 1). The
/// public names (option_specs()) are the stage fields' names. The stages' own `seed` fields are
/// not used by the Extractor: it gives every stage Options::seed.
struct Options {
  PrepareOptions prepare;              ///< stage 0: repair, target_faces, upsample
  VoronoiBallsOptions voronoi;         ///< stage 1: samples
  DomainBallsOptions domain;           ///< stage 2: min_gap, min_radius
  ProngOptions prongs;                 ///< stage 3: tau, geodesic_sources
  ForceFieldOptions field;             ///< stage 4: rays, force_exponent
  ConnectionPointsOptions connection;  ///< stage 5: shrink_step
  RemapOptions remap;                  ///< stage 7: snake_iterations
  WeightsOptions weights;              ///< stage 9: max_influences, heat, min_weight, ...
  unsigned seed = kDefaultSeed;        ///< seed of every randomized step (runs are deterministic)

  /// Stage 0's options with Options::seed: what the skeleton and the weights both prepare with.
  PrepareOptions prepare_options() const;
  /// Throws InputError naming the first option out of range.
  void validate() const;
};

/// One public option: its name (the stage field's), meaning, kind and valid range.
struct OptionSpec {
  enum class Kind { Int, Float, Choice };
  std::string name;
  std::string description;
  std::string stage;  ///< "prepare", "voronoi_balls", ..., "weights"; "all" for seed
  Kind kind = Kind::Float;
  double minimum = 0;  ///< numbers: the valid range, bounds included
  double maximum = 0;
  std::vector<std::string> choices;  ///< Choice: the valid values
  std::string unit;  ///< "" or "normalized length" (fraction of the bounding-box diagonal)
};

/// Every public option, in pipeline order (stage 0 first, the weights last).
const std::vector<OptionSpec>& option_specs();
/// The spec of `name`; InputError for an unknown name.
const OptionSpec& option_spec(const std::string& name);
/// InputError when `value` is outside the range of option `name` (or not whole for an int
/// option): the one range check, used by Options::validate() and by the stages themselves.
void check_option(const std::string& name, double value);

/// Reads / writes a numeric option by name; InputError for an unknown or choice option (set
/// also checks the range).
double get_numeric_option(const Options& options, const std::string& name);
void set_numeric_option(Options& options, const std::string& name, double value);
/// Reads / writes a choice option (repair) by name; InputError for a value not in its choices.
std::string get_choice_option(const Options& options, const std::string& name);
void set_choice_option(Options& options, const std::string& name, const std::string& value);

/// "auto" / "none" <-> Repair; InputError for any other string.
Repair parse_repair(const std::string& text);
const char* repair_name(Repair repair);

}  // namespace dcg
