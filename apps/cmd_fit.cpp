// `oobleck rheology fit`: fit the steady asymptotes of the model to rheometer data with Ceres
// (docs/equations.md, steady rheology; docs/fitting.md; library part in src/oobleck/rheology/fit.hpp):
//   --kind low : (a_0, phi_j) of E12 to minimum viscosities      (columns phi, viscosity | relative_viscosity)
//   --kind high: (a_inf, phi_c) of E13 to plateau viscosities     (same columns)
//   --kind dst : eta_B terms (phi_i, alpha_i) of E8 via E14        (columns phi, shear_rate_dst)
//   --kind curves: a joint fit to whole flow curves (rheology/fit_curves.hpp; columns phi,
//                  shear_rate, shear_stress), or to instrument exports, one --data FILE
//                  [--step NAME|INDEX] --phi PHI per volume fraction (io/rheometer.hpp); parameters
//                  the data do not determine are held at the base values with a warning (--strict:
//                  an error)
// Writes a complete parameter file (the base set with the fitted values replaced, standard errors
// as comments) that loads with --params in every other command.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include "cli_common.hpp"
#include "cmd_fit.hpp"
#include "oobleck/core/error.hpp"
#include "oobleck/io/csv.hpp"
#include "oobleck/io/output_file.hpp"
#include "oobleck/io/rheometer.hpp"
#include "oobleck/rheology/fit.hpp"
#include "oobleck/rheology/fit_curves.hpp"
#include "oobleck/rheology/flow_curve.hpp"
#include "oobleck/rheology/parameter_table.hpp"

namespace oobleck::cli {
namespace {
namespace fs = std::filesystem;

constexpr const char* kDefaultPreset = "hermes2016";

/// Text safe inside a TOML basic string and a comment line: no quotes, backslashes, controls.
std::string sanitize(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '"')
      out += '\'';
    else if (c == '\\')
      out += '/';
    else if (static_cast<unsigned char>(c) < 0x20)
      out += ' ';
    else
      out += c;
  }
  return out;
}

std::string unit_of(const std::string& name) {
  if (name.find("phi_i") != std::string::npos) return "[1/(Pa s)]";
  if (name.find("alpha") != std::string::npos) return "[-]";
  return rheology::unit_label(rheology::parameter(rheology::Section::Steady, name));
}

std::string fmt_se(double se) { return std::isfinite(se) ? fmt::format("{:.3g}", se) : "n/a"; }

struct Data {
  std::vector<double> phi, values;  ///< values: eta_r (low/high) or gamma_dot_DST [1/s] (dst)
  std::string column;               ///< the CSV column the values came from
};

/// Reads phi and the kind's value column; checks the raw values (the library checks the rest).
Data read_data(const std::string& path, rheology::FitKind kind, double eta_0) {
  const io::CsvTable t = io::read_csv(path);
  Data d;
  if (!t.has_column("phi")) {
    throw InputError(fmt::format("{}: missing column 'phi' (columns present: {}); expected phi,{}", path,
                                 fmt::join(t.header, ", "),
                                 kind == rheology::FitKind::dst ? "shear_rate_dst" : "viscosity"));
  }
  double scale = 1.0;
  if (kind == rheology::FitKind::dst) {
    if (!t.has_column("shear_rate_dst")) {
      throw InputError(
          fmt::format("{}: missing column 'shear_rate_dst' [1/s] (columns present: {}); --kind dst "
                      "needs phi,shear_rate_dst",
                      path, fmt::join(t.header, ", ")));
    }
    d.column = "shear_rate_dst";
  } else {
    const bool visc = t.has_column("viscosity"), rel = t.has_column("relative_viscosity");
    if (visc == rel) {
      throw InputError(
          fmt::format("{}: {} (columns present: {}); --kind {} needs phi and exactly one of "
                      "viscosity [Pa s] or relative_viscosity [-]",
                      path,
                      visc ? "both 'viscosity' and 'relative_viscosity' given"
                           : "missing column 'viscosity' or 'relative_viscosity'",
                      fmt::join(t.header, ", "), rheology::to_string(kind)));
    }
    d.column = visc ? "viscosity" : "relative_viscosity";
    if (visc) scale = 1.0 / eta_0;  // eta_r = viscosity/eta_0
  }
  d.phi = t.column("phi");
  const std::vector<double> raw = t.column(d.column);
  for (std::size_t k = 0; k < raw.size(); ++k) {
    if (!(d.phi[k] > 0.0 && d.phi[k] < 1.0)) {
      throw InputError(fmt::format("{}: data row {}: column 'phi' = {}: must lie in (0, 1)", path, k + 1, d.phi[k]));
    }
    if (!(raw[k] > 0.0)) {
      throw InputError(
          fmt::format("{}: data row {}: column '{}' = {}: must be positive", path, k + 1, d.column, raw[k]));
    }
    d.values.push_back(raw[k] * scale);
  }
  return d;
}

/// Header comments of the fitted parameter file: what was fitted, with standard errors.
std::string toml_header(const rheology::FitResult& r, const std::string& data, const std::string& base) {
  std::string h = fmt::format("# oobleck parameter set fitted by: oobleck rheology fit --kind {} --data {}\n",
                              rheology::to_string(r.kind), sanitize(data));
  h += fmt::format("# base set: {}; every value not listed below is the base value (mu_c is never fitted)\n",
                   sanitize(base));
  h += "# fitted values with 1-sigma standard errors (Ceres covariance scaled by s^2 = 2 cost/(n - p)):\n";
  for (const auto& p : r.parameters) {
    h += fmt::format("#   {} = {:.8g} +- {} {}\n", p.name, p.value, fmt_se(p.std_error), unit_of(p.name));
  }
  h += fmt::format("# n = {} points, p = {} parameters, rms log residual = {:.4g}\n\n", r.n, r.p, r.rms);
  return h;
}

/// Data (with the fitted model) and a fine model curve for tools/plot_fit.py, then the plot,
/// written to a temporary PNG beside `png`; returns the temporary's path.
std::string plot_fit(const rheology::FitResult& r, const Data& d, const std::string& title, const std::string& png) {
  using rheology::FitKind;
  const fs::path dir = fs::temp_directory_path();
  const std::string stem = fmt::format("oobleck-fit-{}", ::getpid());
  const std::string data_csv = (dir / (stem + "-data.csv")).string();
  const std::string curve_csv = (dir / (stem + "-curve.csv")).string();
  TempFiles cleanup;
  cleanup.files = {data_csv, curve_csv};

  std::string s = "phi,data,model\n";
  for (std::size_t k = 0; k < d.phi.size(); ++k) {
    s += fmt::format("{},{},{}\n", num(d.phi[k]), num(d.values[k]),
                     num(rheology::fit_model_value(r.kind, r.params, d.phi[k])));
  }
  io::write_file_atomically(data_csv, s, "plot data");

  // Curve up to the asymptote phi_m (E12: phi_j, E13: phi_c, E14: phi_j), log-spaced in the gap.
  const double phi_lo = *std::min_element(d.phi.begin(), d.phi.end());
  const double phi_hi = *std::max_element(d.phi.begin(), d.phi.end());
  const double phi_m = r.kind == FitKind::high ? r.params.phi_c : r.params.phi_j;
  const double start = r.kind == FitKind::dst ? r.params.phi_c : std::max(0.0, phi_lo - 0.05 * (phi_m - phi_lo));
  const double gap_hi = phi_m - start;
  const double gap_lo =
      r.kind == FitKind::dst ? 0.5 * (phi_m - phi_hi) : std::min(0.5 * (phi_m - phi_hi), 1e-3 * gap_hi);
  std::string c = "phi,model\n";
  constexpr int kPoints = 300;
  for (int k = 0; k < kPoints; ++k) {
    const double gap = gap_hi * std::pow(gap_lo / gap_hi, double(k) / (kPoints - 1));
    const double phi = phi_m - gap;
    const double v = rheology::fit_model_value(r.kind, r.params, phi);
    if (std::isfinite(v)) c += fmt::format("{},{}\n", num(phi), num(v));
  }
  io::write_file_atomically(curve_csv, c, "plot curve");

  std::string tmp = png + ".tmp.png";
  try {
    run_tool("plot_fit.py", {data_csv, curve_csv, "--kind", rheology::to_string(r.kind), "--phi-m", num(phi_m),
                             "--title", title, tmp});
  } catch (...) {
    std::error_code ec;
    fs::remove(tmp, ec);
    throw;
  }
  return tmp;
}

/// `--kind curves`: the joint fit of whole flow curves (rheology/fit_curves.hpp).
struct CurvesOpts {
  std::string data, out, parameters, residual, png;  ///< data: the file(s), ", "-separated
  bool json = false;
  bool strict = false;  ///< undetermined parameters are an error instead of held
  std::string args;     ///< the exports' --data/--step/--phi options ("" for one CSV)
  /// The data files' names without folders, ", "-separated.
  std::string names() const {
    std::string n, item;
    for (char c : data + ",") {
      if (c != ',') {
        item += c;
        continue;
      }
      const std::string f = fs::path(item.substr(item.find_first_not_of(' '))).filename().string();
      n += (n.empty() ? "" : ", ") + f;
      item.clear();
    }
    return n;
  }
};

/// One volume fraction's export: --data FILE [--step NAME|INDEX] --phi PHI.
struct Export {
  std::string file, step;
  double phi = 0.0;
};

/// The table of `--kind curves`: the data CSV (columns phi, shear_rate, shear_stress) or, with
/// --phi, the exports' flow-curve rows (io::flow_curve_rows) with their phi, in the same columns.
io::CsvTable curves_table(const std::vector<Export>& exports, const std::string& csv, bool quiet) {
  if (exports.empty()) {
    std::optional<InputError> csv_error;
    try {
      io::CsvTable t = io::read_csv(csv);
      if (t.has_column("phi")) return t;
    } catch (const InputError& e) {
      csv_error = e;
    }
    // Not a CSV with a phi column: an instrument export is named with what it needs.
    io::RheometerFormat format = io::RheometerFormat::csv;
    try {
      format = io::read_rheometer(csv).format;
    } catch (const InputError&) {
    }
    if (format != io::RheometerFormat::csv) {
      throw InputError(
          fmt::format("{}: a {} export has no phi column: give its volume fraction after it, --data {} "
                      "--phi PHI [--step NAME|INDEX] (one --data and --phi per volume fraction)",
                      csv, io::to_string(format), csv));
    }
    if (csv_error) throw *csv_error;
    return io::read_csv(csv);  // without phi: the missing column is named below
  }
  io::CsvTable t;
  t.header = {"phi", "shear_rate", "shear_stress"};
  for (const auto& e : exports) {
    t.file += (t.file.empty() ? "" : ", ") + e.file;
    const io::RheometerFile f = io::read_rheometer(e.file);
    for (const auto& st : f.steps) {
      if (st.find("phi") != nullptr)
        throw InputError(
            fmt::format("{}: has a column 'phi' and --phi = {} was given: give one of them", e.file, e.phi));
    }
    const io::FlowCurveRows rows = io::flow_curve_rows(f, e.step, "--step");
    for (std::size_t k = 0; k < rows.shear_rate.size(); ++k)
      t.rows.push_back({e.phi, rows.shear_rate[k], rows.shear_stress[k]});
    if (!quiet) {
      std::vector<std::string> names;
      for (std::size_t s : rows.steps) names.push_back(fmt::format("'{}'", f.steps[s].name));
      fmt::print(
          "{} ({}): phi = {}, {} points from step {}{}\n", e.file, io::to_string(f.format), e.phi,
          rows.shear_rate.size(), fmt::join(names, ", "),
          rows.skipped ? fmt::format(" ({} rows without both shear rate and stress skipped)", rows.skipped) : "");
    }
  }
  return t;
}

}  // namespace

FlowCurveData read_flow_curve_data(const CLI::App& cmd, const CLI::Option* data, const CLI::Option* step,
                                   const std::vector<std::string>& files, const std::vector<std::string>& steps,
                                   const std::vector<double>& phi, bool quiet) {
  // --data FILE [--step S] --phi PHI per volume fraction: a --step belongs to the --data before it.
  std::vector<Export> exports;
  std::string args;
  if (!phi.empty() || files.size() > 1 || step->count() > 0) {
    if (phi.size() != files.size())
      throw InputError(
          fmt::format("--data given {} times and --phi {} times: give one --phi (the volume fraction) "
                      "per --data export, e.g. --data a.txt --phi 0.40 --data b.txt --phi 0.44",
                      files.size(), phi.size()));
    std::string every;
    std::vector<std::string> of_file(files.size());
    std::size_t k = 0, j = 0;
    for (const CLI::Option* opt : cmd.parse_order()) {
      if (opt == data) ++k;
      if (opt == step && j < steps.size()) (k == 0 ? every : of_file[k - 1]) = steps[j++];
    }
    for (std::size_t i = 0; i < files.size(); ++i) {
      exports.push_back({files[i], of_file[i].empty() ? every : of_file[i], phi[i]});
      args += fmt::format("{}--data {}{} --phi {}", i ? " " : "", files[i],
                          exports.back().step.empty() ? "" : fmt::format(" --step '{}'", exports.back().step), phi[i]);
    }
  }
  return {curves_table(exports, fmt::format("{}", fmt::join(files, ", ")), quiet), args};
}

namespace {

/// `--kind curves --plot`: the data (with the model's value and the residual per point) and the
/// fitted flow curves at each data phi (every branch, 300 points, cut to the data's stress range
/// widened by 3x) for tools/plot_fit.py, then the plot, written to a temporary PNG beside `png`;
/// returns the temporary's path.
std::string plot_curves_fit(const rheology::CurvesFitResult& r, const io::CsvTable& t,
                            rheology::CurvesResidual residual, const std::string& title, const std::string& png) {
  const fs::path dir = fs::temp_directory_path();
  const std::string stem = fmt::format("oobleck-fit-{}", ::getpid());
  const std::string data_csv = (dir / (stem + "-data.csv")).string();
  const std::string curve_csv = (dir / (stem + "-curve.csv")).string();
  TempFiles cleanup;
  cleanup.files = {data_csv, curve_csv};

  const std::vector<double> phi = t.column("phi"), rate = t.column("shear_rate"), stress = t.column("shear_stress");
  std::string s = "phi,shear_rate,shear_stress,model,residual\n";
  for (std::size_t k = 0; k < phi.size(); ++k) {
    s += fmt::format("{},{},{},{},{}\n", num(phi[k]), num(rate[k]), num(stress[k]), num(r.model[k]),
                     num(r.residuals[k]));
  }
  io::write_file_atomically(data_csv, s, "plot data");

  std::vector<double> phis = phi;
  std::sort(phis.begin(), phis.end());
  phis.erase(std::unique(phis.begin(), phis.end()), phis.end());
  std::string c = "phi,shear_rate,shear_stress\n";
  for (double x : phis) {
    double lo = INFINITY, hi = 0.0;
    for (std::size_t k = 0; k < phi.size(); ++k) {
      if (phi[k] == x) {
        lo = std::min(lo, stress[k]);
        hi = std::max(hi, stress[k]);
      }
    }
    for (const auto& pt : rheology::flow_curve(r.fitted.steady, x, 300)) {
      if (pt.shear_stress > lo / 3.0 && pt.shear_stress < 3.0 * hi && std::isfinite(pt.shear_rate))
        c += fmt::format("{},{},{}\n", num(x), num(pt.shear_rate), num(pt.shear_stress));
    }
  }
  io::write_file_atomically(curve_csv, c, "plot curve");

  std::string tmp = png + ".tmp.png";
  try {
    run_tool("plot_fit.py", {data_csv, curve_csv, "--kind", "curves", "--residual", rheology::to_string(residual),
                             "--title", title, tmp});
  } catch (...) {
    std::error_code ec;
    fs::remove(tmp, ec);
    throw;
  }
  return tmp;
}

std::string held_names(const rheology::CurvesFitResult& r) {
  std::vector<std::string> names;
  for (const auto& p : r.held) names.push_back(p.name);
  return fmt::format("{}", fmt::join(names, ", "));
}

/// Writes the parameter file `out`, then moves the plot's temporary `tmp_png` (none: "") to `png`;
/// a failed write removes the temporary.
void write_fit_files(const std::string& out, const std::string& toml, const std::string& tmp_png,
                     const std::string& png) {
  try {
    io::write_file_atomically(out, toml, "--out");
  } catch (...) {
    if (!tmp_png.empty()) {
      std::error_code ec;
      fs::remove(tmp_png, ec);
    }
    throw;
  }
  if (!tmp_png.empty()) fs::rename(tmp_png, png);
}

/// The fitted parameters, one a line (value, standard error, unit, relative error), names padded
/// to the longest; returns that width.
std::size_t print_parameters(const std::vector<rheology::FittedParameter>& parameters) {
  std::size_t width = 0;
  for (const auto& p : parameters) width = std::max(width, p.name.size());
  for (const auto& p : parameters) {
    const double rel = std::abs(p.std_error / p.value);
    fmt::print("  {:<{}} = {:<12.6g} +- {:<10}  {:<11}{}\n", p.name, width, p.value, fmt_se(p.std_error),
               unit_of(p.name), std::isfinite(rel) ? fmt::format("({:.2g} %)", 100.0 * rel) : "");
  }
  return width;
}

/// --parameters: the comma-separated names, spaces dropped.
std::vector<std::string> parameter_list(const std::string& text) {
  std::vector<std::string> names;
  if (text.empty()) return names;
  std::string item;
  for (char c : text + ",") {
    if (c == ',') {
      if (!item.empty()) names.push_back(item);
      item.clear();
    } else if (c != ' ') {
      item += c;
    }
  }
  return names;
}

/// Header comments of the curves fit's parameter file: what was fitted, with standard errors, and
/// what was held.
std::string curves_toml_header(const CurvesOpts& o, const rheology::CurvesFitResult& r, const rheology::Preset& preset,
                               rheology::CurvesResidual residual) {
  std::string h = fmt::format("# oobleck parameter set fitted by: oobleck rheology fit --kind curves {}\n",
                              sanitize(o.args.empty() ? "--data " + o.data : o.args));
  h += fmt::format("# base set: {} ({}); every value not listed below is the base value\n", sanitize(preset.name),
                   sanitize(preset.file));
  h += fmt::format(
      "# fitted values with 1-sigma standard errors ((J^T J)^-1 s^2, s^2 = 2 cost/(n - p)); residual: ln {}\n",
      rheology::to_string(residual) == "rate" ? "shear rate at the measured stress"
                                              : "shear stress at the measured rate");
  for (const auto& p : r.parameters) {
    h += fmt::format("#   {} = {:.8g} +- {} {}\n", p.name, p.value, fmt_se(p.std_error), unit_of(p.name));
  }
  if (!r.held.empty()) {
    h += "# held at the base set's values because the data do not determine them (--strict: an error instead):\n";
    for (const auto& p : r.held) {
      h += fmt::format("#   {} = {:.8g} {}: {}\n", p.name, p.value, unit_of(p.name), sanitize(p.reason));
    }
  }
  h += fmt::format("# n = {} points, p = {} parameters, rms log residual = {:.4g}\n\n", r.n, r.p, r.rms);
  return h;
}

/// The curves fit's result: one JSON object (--json) or the text report.
void print_curves_result(const CurvesOpts& o, const rheology::CurvesFitResult& r, const rheology::Preset& preset,
                         rheology::CurvesResidual residual, const std::string& note) {
  if (o.json) {
    nlohmann::json params = nlohmann::json::object();
    for (const auto& p : r.parameters) params[p.name] = {{"value", p.value}, {"std_error", p.std_error}};
    nlohmann::json j = {{"kind", "curves"},
                        {"parameters", params},
                        {"n", r.n},
                        {"rms", r.rms},
                        {"iterations", r.iterations},
                        {"base", preset.name},
                        {"out", o.out},
                        {"residual", rheology::to_string(residual)},
                        {"correlation", r.correlation}};
    nlohmann::json order = nlohmann::json::array();  // "parameters" is an object: its keys come sorted
    for (const auto& p : r.parameters) order.push_back(p.name);
    j["correlation_order"] = order;
    nlohmann::json held = nlohmann::json::array();
    for (const auto& p : r.held) held.push_back({{"name", p.name}, {"value", p.value}, {"reason", p.reason}});
    j["held"] = held;
    if (!note.empty()) j["note"] = note;
    fmt::print("{}\n", j.dump());
    return;
  }
  fmt::print("base parameter set: {} ({}) [{} units]\n", preset.name, preset.file, preset.units);
  fmt::print("fit --kind curves to {}: n = {} points, p = {} parameters; Ceres converged ({} iterations)\n", o.data,
             r.n, r.p, r.iterations);
  const std::size_t width = print_parameters(r.parameters);
  for (const auto& p : r.held) {
    fmt::print("  {:<{}} = {:<12.6g} held (base value)  {}\n", p.name, width, p.value, unit_of(p.name));
  }
  fmt::print("rms log residual = {:.4g} (n = {}, residual: ln {})\n", r.rms, r.n, rheology::to_string(residual));
  fmt::print("wrote {}\n", o.out);
  if (!o.png.empty()) fmt::print("wrote {}\n", o.png);
}

void fit_curves_command(const CurvesOpts& o, const io::CsvTable& t, rheology::Preset preset, const std::string& note) {
  for (const char* c : {"phi", "shear_rate", "shear_stress"}) {
    if (!t.has_column(c)) {
      throw InputError(
          fmt::format("{}: missing column '{}' (columns present: {}); --kind curves needs "
                      "phi,shear_rate,shear_stress",
                      o.data, c, fmt::join(t.header, ", ")));
    }
  }
  rheology::CurvesFitOptions options;
  options.where = o.data;
  options.residual = rheology::parse_curves_residual(o.residual, "--residual");
  options.strict = o.strict;
  options.parameters = parameter_list(o.parameters);
  io::check_writable(o.out, "--out");
  if (!o.png.empty()) io::check_writable(o.png, "--plot");
  const auto r =
      rheology::fit_curves(t.column("phi"), t.column("shear_rate"), t.column("shear_stress"), preset, options);
  rheology::Preset fitted = r.fitted;
  fitted.name = sanitize(fs::path(o.out).stem().string());
  fitted.source = sanitize(
      fmt::format("oobleck rheology fit --kind curves to {}; base {}: {}", o.names(), preset.name, preset.source));
  const std::string h = curves_toml_header(o, r, preset, options.residual);
  // The warning goes to stderr in both output modes, before anything is written.
  for (const auto& p : r.held) {
    fmt::print(stderr, "warning: {} held at the base value {:.6g} {}: the data do not determine it ({})\n", p.name,
               p.value, unit_of(p.name), p.reason);
  }
  if (!r.held.empty()) {
    fmt::print(stderr, "warning: {} of {} parameters held ({}); --strict makes this an error\n", r.held.size(),
               r.held.size() + r.parameters.size(), held_names(r));
  }
  std::string tmp_png;
  if (!o.png.empty()) {
    tmp_png = plot_curves_fit(r, t, options.residual,
                              fmt::format("{}: fit --kind curves (base {}){}", o.names(), preset.name,
                                          r.held.empty() ? "" : "\nheld at the base values: " + held_names(r)),
                              o.png);
  }
  write_fit_files(o.out, h + rheology::to_toml(fitted), tmp_png, o.png);
  print_curves_result(o, r, preset, options.residual, note);
}

/// The options of `oobleck rheology fit`, with the ones whose presence the kinds check.
struct FitArgs {
  ParamsOption params;
  std::string kind, data, out, png;
  std::vector<std::string> files, steps;
  std::vector<double> phi;
  int terms = 0;
  bool json = false, strict = false;
  std::string parameters, residual = "rate";
  CLI::App* cmd = nullptr;
  CLI::Option *data_opt = nullptr, *phi_opt = nullptr, *step_opt = nullptr, *terms_opt = nullptr;
  CLI::Option *parameters_opt = nullptr, *residual_opt = nullptr, *strict_opt = nullptr;

  /// True when neither --preset nor --params is given (the default base, with a note).
  bool default_base() const { return params.preset.empty() && params.params.empty(); }
};

std::string default_base_note() {
  return fmt::format("no --preset or --params given: using the {} preset as the base parameter set", kDefaultPreset);
}

/// `--kind curves`: the joint fit of whole flow curves from a CSV or instrument exports.
void fit_kind_curves(const FitArgs& a) {
  if (a.terms_opt->count() > 0)
    throw InputError(fmt::format("--terms = {}: only for --kind dst (not curves)", a.terms));
  std::string note;
  if (a.default_base()) {
    note = default_base_note();
    fmt::print(a.json ? stderr : stdout, "{}\n", note);
  }
  const rheology::Preset base = a.params.load(kDefaultPreset);
  const FlowCurveData d = read_flow_curve_data(*a.cmd, a.data_opt, a.step_opt, a.files, a.steps, a.phi, a.json);
  fit_curves_command({a.data, a.out, a.parameters, a.residual, a.png, a.json, a.strict, d.args}, d.table, base, note);
}

/// The warning for an asymptote fit whose rms log residual exceeds 0.1, with what to check; "" below.
std::string rms_warning(const rheology::FitResult& r, rheology::FitKind kind, const rheology::Preset& preset) {
  if (!(r.rms > 0.1)) return "";
  const std::string hint =
      kind == rheology::FitKind::dst
          ? fmt::format(
                "check the units (shear_rate_dst in 1/s), the base set (phi_c, phi_j, tau_star, eta_0 = "
                "{} Pa s) and the number of eta_B terms (--terms)",
                preset.steady.eta_0)
          : fmt::format(
                "check the units (viscosity in Pa s, eta_0 = {} Pa s of the base set) and that the "
                "points are {} viscosities",
                preset.steady.eta_0, kind == rheology::FitKind::low ? "minimum" : "plateau (maximum)");
  return fmt::format(
      "warning: rms log residual {:.3g} > 0.1 (more than 10 % scatter): the fitted {} "
      "asymptote does not describe these data well; {}",
      r.rms, rheology::to_string(kind), hint);
}

/// An asymptote fit's result: one JSON object (--json; the warning on stderr) or the text report.
void print_asymptote_result(const FitArgs& a, const rheology::FitResult& r, rheology::FitKind kind,
                            const rheology::Preset& preset, const std::string& note) {
  const std::string warning = rms_warning(r, kind, preset);
  if (a.json) {
    if (!warning.empty()) fmt::print(stderr, "{}\n", warning);
    nlohmann::json params = nlohmann::json::object();
    for (const auto& p : r.parameters) {
      params[p.name] = {{"value", p.value},
                        {"std_error", std::isfinite(p.std_error) ? nlohmann::json(p.std_error) : nlohmann::json()}};
    }
    nlohmann::json j = {{"kind", rheology::to_string(kind)}, {"parameters", params}, {"n", r.n},    {"rms", r.rms},
                        {"iterations", r.iterations},        {"base", preset.name},  {"out", a.out}};
    if (!note.empty()) j["note"] = note;
    fmt::print("{}\n", j.dump());
    return;
  }
  fmt::print("base parameter set: {} ({}) [{} units]; mu_c = {} (fixed)\n", preset.name, preset.file, preset.units,
             preset.steady.mu_c);
  fmt::print("fit --kind {} to {}: n = {} points, p = {} parameters; Ceres converged ({} iterations)\n", a.kind, a.data,
             r.n, r.p, r.iterations);
  print_parameters(r.parameters);
  if (!r.covariance_ok) {
    fmt::print(
        "  standard errors n/a: the parameters are not all identifiable from these data (rank-deficient "
        "Jacobian){}\n",
        kind == rheology::FitKind::dst ? "; fit fewer eta_B terms (--terms)" : "");
  }
  fmt::print("rms log residual = {:.4g} (n = {})\n", r.rms, r.n);
  if (!warning.empty()) fmt::print("{}\n", warning);
  fmt::print("wrote {}\n", a.out);
  if (!a.png.empty()) fmt::print("wrote {}\n", a.png);
}

/// `--kind low`, `high` and `dst`: the asymptote `kind` (E12, E13, E14) fitted to one CSV.
void fit_kind_asymptote(const FitArgs& a, rheology::FitKind kind) {
  rheology::FitOptions options;
  if (a.terms_opt->count() > 0) {
    if (kind != rheology::FitKind::dst) {
      throw InputError(fmt::format("--terms = {}: only for --kind dst (not {})", a.terms, a.kind));
    }
    if (a.terms < 1) throw InputError(fmt::format("--terms = {}: must be >= 1", a.terms));
    options.terms = a.terms;
  }
  const rheology::Preset preset = a.params.load(kDefaultPreset);
  std::string note;
  if (a.default_base()) {
    note = default_base_note();
    fmt::print(a.json ? stderr : stdout, "{}\n", note);
  }
  const Data d = read_data(a.data, kind, preset.steady.eta_0);
  options.where = a.data;
  rheology::validate_fit_data(kind, d.phi, d.values, preset.steady, options);
  io::check_writable(a.out, "--out");
  if (!a.png.empty()) io::check_writable(a.png, "--plot");

  const rheology::FitResult r = rheology::fit(kind, d.phi, d.values, preset.steady, options);

  rheology::Preset fitted = preset;
  fitted.steady = r.params;
  fitted.name = sanitize(fs::path(a.out).stem().string());
  fitted.source = sanitize(fmt::format("oobleck rheology fit --kind {} to {}; base {}: {}", a.kind,
                                       fs::path(a.data).filename().string(), preset.name, preset.source));
  try {
    rheology::validate(fitted, a.out);
  } catch (const InputError& e) {
    throw NumericalError(fmt::format("the fitted parameters break a rule: {}", e.what()));
  }
  std::string tmp_png;
  if (!a.png.empty()) {
    tmp_png = plot_fit(
        r, d, fmt::format("{}: fit --kind {} (base {})", fs::path(a.data).filename().string(), a.kind, preset.name),
        a.png);
  }
  const std::string base_desc = fmt::format("{} ({})", preset.name, preset.file);
  write_fit_files(a.out, toml_header(r, a.data, base_desc) + rheology::to_toml(fitted), tmp_png, a.png);
  print_asymptote_result(a, r, kind, preset, note);
}

/// Checks --kind and the options that belong to other kinds, then runs the kind's fit.
void run_fit(FitArgs& a) {
  if (a.kind != "low" && a.kind != "high" && a.kind != "dst" && a.kind != "curves") {
    throw InputError(
        fmt::format("--kind = '{}': must be one of low (a_0, phi_j from minimum viscosities, E12), high (a_inf, "
                    "phi_c from plateau viscosities, E13), dst (eta_B terms from DST rates, E14), curves (joint "
                    "fit to whole flow curves: phi, shear_rate, shear_stress)",
                    a.kind));
  }
  if (a.kind != "curves") {
    for (auto* opt : {a.phi_opt, a.step_opt}) {
      if (opt->count() > 0)
        throw InputError(
            fmt::format("{}: only for --kind curves with instrument exports (not {})", opt->get_name(), a.kind));
    }
    if (a.files.size() != 1)
      throw InputError(fmt::format("--data given {} times: --kind {} reads one CSV", a.files.size(), a.kind));
  }
  a.data = fmt::format("{}", fmt::join(a.files, ", "));
  if (a.kind == "curves") {
    fit_kind_curves(a);
    return;
  }
  for (auto* opt : {a.parameters_opt, a.residual_opt, a.strict_opt}) {
    if (opt->count() > 0) throw InputError(fmt::format("{}: only for --kind curves (not {})", opt->get_name(), a.kind));
  }
  fit_kind_asymptote(a, rheology::parse_fit_kind(a.kind, "--kind"));
}

}  // namespace

void add_fit_command(CLI::App& rheology) {
  auto* cmd = rheology.add_subcommand(
      "fit",
      "fit model parameters to rheometer data with Ceres: low (a_0, phi_j; E12), high (a_inf, phi_c; E13), "
      "dst (eta_B terms; E14), curves (joint fit of whole flow curves)");
  auto a = std::make_shared<FitArgs>();
  a->cmd = cmd;
  cmd->add_option("--kind", a->kind, "low | high | dst | curves")->required();
  a->data_opt = cmd->add_option("--data", a->files,
                                "CSV with columns phi,viscosity [Pa s] or phi,relative_viscosity (low, high); "
                                "phi,shear_rate_dst [1/s] (dst); phi,shear_rate [1/s],shear_stress [Pa] (curves); "
                                "curves: or an instrument export (TRIOS, RheoCompass, rSpace, CSV with units) with "
                                "--phi, repeated once per volume fraction")
                    ->required();
  a->phi_opt = cmd->add_option("--phi", a->phi,
                               "curves only: the volume fraction of the --data export before it (one per --data)");
  a->step_opt = cmd->add_option("--step", a->steps,
                                "curves only: the export's step, NAME (case-insensitive, TRIOS's ' - N' optional) or "
                                "1-based INDEX; after a --data for that file, before the first --data for all "
                                "(default: the one step with shear rate and stress)");
  a->params.add_to(cmd);
  cmd->add_option("--out", a->out, "fitted parameter file (TOML) to write")->required();
  cmd->add_option("--plot", a->png,
                  "also plot data and fitted curve (curves: the flow curves and the residuals) to this PNG");
  a->terms_opt = cmd->add_option("--terms", a->terms,
                                 "dst only: number of eta_B terms to fit (default: as many as the base set has, or 1)");
  cmd->add_flag("--json", a->json,
                "print one JSON object {\"kind\", \"parameters\": {name: {\"value\", \"std_error\"}}, \"n\", \"rms\"}");
  a->parameters_opt = cmd->add_option(
      "--parameters", a->parameters,
      "curves only: fitted parameters, comma-separated (default a_0,phi_j,a_inf,phi_c,tau_star and every eta_B term)");
  a->residual_opt = cmd->add_option("--residual", a->residual,
                                    "curves only: rate (ln shear rate at the measured stress) or stress (ln shear "
                                    "stress at the measured rate)");
  a->strict_opt = cmd->add_flag("--strict", a->strict,
                                "curves only: a parameter the data do not determine is an error (default: it is held "
                                "at the base set's value, with a warning naming it)");
  cmd->callback([a] { run_fit(*a); });
}

}  // namespace oobleck::cli
