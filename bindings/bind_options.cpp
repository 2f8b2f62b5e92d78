// The option table (dcg/options.h) for Python: specs, defaults, and dict <-> dcg::Options. The
// Python package builds dcg.OPTIONS, the CLI flags and the add-on's properties from these.
#include "common.h"

#include "dcg/options.h"

namespace dcg_py {

dcg::Options options_from_dict(const py::dict& values) {
  dcg::Options options;
  for (const auto& item : values) {
    const std::string name = py::str(item.first);
    if (dcg::option_spec(name).kind == dcg::OptionSpec::Kind::Choice) {
      dcg::set_choice_option(options, name, py::str(item.second));
    } else {
      dcg::set_numeric_option(options, name, option_number(name, item.second));
    }
  }
  return options;
}

py::dict options_to_dict(const dcg::Options& options) {
  py::dict out;
  for (const auto& spec : dcg::option_specs()) {
    if (spec.kind == dcg::OptionSpec::Kind::Choice) {
      out[spec.name.c_str()] = dcg::get_choice_option(options, spec.name);
    } else if (spec.kind == dcg::OptionSpec::Kind::Int) {
      out[spec.name.c_str()] = static_cast<long long>(dcg::get_numeric_option(options, spec.name));
    } else {
      out[spec.name.c_str()] = dcg::get_numeric_option(options, spec.name);
    }
  }
  return out;
}

namespace {

const char* kind_name(dcg::OptionSpec::Kind kind) {
  switch (kind) {
    case dcg::OptionSpec::Kind::Int:
      return "int";
    case dcg::OptionSpec::Kind::Float:
      return "float";
    case dcg::OptionSpec::Kind::Choice:
      return "choice";
  }
  return "float";
}

py::list option_specs() {
  py::list out;
  for (const auto& spec : dcg::option_specs()) {
    py::dict d;
    d["name"] = spec.name;
    d["description"] = spec.description;
    d["stage"] = spec.stage;
    d["kind"] = kind_name(spec.kind);
    d["minimum"] = spec.minimum;
    d["maximum"] = spec.maximum;
    d["choices"] = py::tuple(py::cast(spec.choices));
    d["unit"] = spec.unit;
    out.append(d);
  }
  return out;
}

}  // namespace

void bind_options(py::module_& m) {
  m.def("option_specs", &option_specs,
        "Every option: name, description, stage, kind, range or choices, unit.");
  m.def(
      "default_options", [] { return options_to_dict(dcg::Options{}); },
      "Every option with its default value.");
  m.def(
      "normalize_options",
      [](const py::dict& values) { return options_to_dict(options_from_dict(values)); },
      "Checks options (ValueError when out of range) and returns the full set with defaults.");
}

}  // namespace dcg_py
