// `oobleck rheology ...`: steady rheology of the model (docs/equations.md, steady rheology): flow curves with every
// branch, the DST shear rate, the f(tau) comparison, the mass-to-volume fraction conversion, and
// `import`: a rheometer's export file as one CSV in SI (io/rheometer.hpp).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <initializer_list>
#include <sstream>

#include <unistd.h>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "cli_common.hpp"
#include "cmd_fit.hpp"
#include "oobleck/core/error.hpp"
#include "oobleck/io/output_file.hpp"
#include "oobleck/io/rheometer.hpp"
#include "oobleck/rheology/flow_curve.hpp"
#include "oobleck/rheology/structure_evolution.hpp"
#include "oobleck/rheology/volume_fraction.hpp"

namespace oobleck::cli {
namespace {

/// "LO,HI" of --xlim/--ylim: 0 < LO < HI, finite (log axes); a usage error otherwise.
std::string parse_limits(const std::string& text, const std::string& option) {
  const auto comma = text.find(',');
  double lo = NAN, hi = NAN;
  if (comma != std::string::npos) {
    try {
      std::size_t n1 = 0, n2 = 0;
      const std::string a = text.substr(0, comma), b = text.substr(comma + 1);
      lo = std::stod(a, &n1);
      hi = std::stod(b, &n2);
      if (n1 != a.size() || n2 != b.size()) lo = hi = NAN;
    } catch (const std::exception&) {
      lo = hi = NAN;
    }
  }
  if (!(std::isfinite(lo) && std::isfinite(hi) && lo > 0.0 && lo < hi)) {
    throw CLI::ValidationError(
        option,
        fmt::format("'{}': must be LO,HI with 0 < LO < HI (the axes are logarithmic), e.g. {} 1e-3,1e2", text, option));
  }
  return fmt::format("{},{}", num(lo), num(hi));
}

/// The `# units: ...` first line of the flow-curve CSV (SI, or the normalized units of the Singh sets).
std::string flow_curve_units(const rheology::Preset& p) {
  const bool si = p.units != "normalized";
  const std::string rate = si ? "1/s" : "gamma_dot_0", stress = si ? "Pa" : "eta_0 gamma_dot_0",
                    visc = si ? "Pa s" : "eta_0";
  return fmt::format(
      "# units: phi=1, f=1, shear_rate={0}, shear_stress={1}, granular_pressure={1}, granular_shear_stress={1}, "
      "viscosity={2}, eta_r=1, shear_rate_dst={0}; parameters {3} ({4} units)\n",
      rate, stress, visc, p.name, p.units);
}

/// The volume fractions of measured flow curves (--data), sorted and distinct; InputError if a
/// column is missing or a rate or stress is not positive.
std::vector<double> measured_phis(const io::CsvTable& t) {
  for (const char* c : {"phi", "shear_rate", "shear_stress"}) {
    if (!t.has_column(c)) {
      throw InputError(
          fmt::format("{}: missing column '{}' (columns present: {}); --data needs phi,shear_rate,shear_stress (or an "
                      "instrument export with --phi)",
                      t.file, c, fmt::join(t.header, ", ")));
    }
  }
  std::vector<double> phis = t.column("phi");
  const std::vector<double> rate = t.column("shear_rate"), stress = t.column("shear_stress");
  for (std::size_t k = 0; k < phis.size(); ++k) {
    if (!(rate[k] > 0.0 && stress[k] > 0.0 && std::isfinite(rate[k]) && std::isfinite(stress[k]))) {
      throw InputError(fmt::format("{}: data row {}: shear_rate = {}, shear_stress = {}: must be positive", t.file,
                                   k + 1, rate[k], stress[k]));
    }
  }
  std::sort(phis.begin(), phis.end());
  phis.erase(std::unique(phis.begin(), phis.end()), phis.end());
  return phis;
}

/// The flow-curve CSV (rheology::flow_curve_columns, E11 and E14) at each phi; `what` names the
/// file in messages.
void write_flow_curves(const std::string& path, const std::string& what, const rheology::Preset& p,
                       const std::vector<double>& phis, int points) {
  const std::vector<double> c = rheology::flow_curve_columns(p.steady, phis, points);
  const std::size_t rows = c.size() / rheology::kFlowCurveColumns.size();
  io::OutputFile csv(path, what);
  auto& s = csv.stream();
  s << flow_curve_units(p);
  s << fmt::format("{}\n", fmt::join(rheology::kFlowCurveColumns, ","));
  for (std::size_t i = 0; i < rows; ++i) {
    s << fmt::format("{},{},{},{},{},{},{},{},{}\n", num(c[i]), num(c[rows + i]), num(c[2 * rows + i]),
                     num(c[3 * rows + i]), num(c[4 * rows + i]), num(c[5 * rows + i]), num(c[6 * rows + i]),
                     num(c[7 * rows + i]), num(c[8 * rows + i]));
  }
  csv.commit();
}

/// The measured points of --data as the plot script's data CSV.
void write_plot_data(const std::string& path, const io::CsvTable& t) {
  const std::vector<double> phi = t.column("phi"), rate = t.column("shear_rate"), stress = t.column("shear_stress");
  std::string d = "# units: phi=1, shear_rate=1/s, shear_stress=Pa; measured: " + t.file + "\n";
  d += "phi,shear_rate,shear_stress\n";
  for (std::size_t k = 0; k < phi.size(); ++k)
    d += fmt::format("{},{},{}\n", num(phi[k]), num(rate[k]), num(stress[k]));
  io::write_file_atomically(path, d, "plot data");
}

/// The options of `rheology flow-curve`.
struct FlowCurveOpts {
  ParamsOption params;
  std::vector<double> phi;
  int points = 400;
  std::string out, png, x = "rate", y = "stress", xlim, ylim;
  std::vector<std::string> files, steps;
};

/// The usage rules of `rheology flow-curve` (CLI::ValidationError, exit 1): something to write,
/// the options in `draw_only` only with --plot, distinct axes, --step only with --data.
void check_flow_curve_usage(const FlowCurveOpts& o, std::initializer_list<const CLI::Option*> draw_only,
                            const CLI::Option* data, const CLI::Option* step) {
  if (o.out.empty() && o.png.empty()) {
    throw CLI::ValidationError("--out/--plot", "give --out CSV, --plot PNG or both (nothing to write)");
  }
  if (o.png.empty()) {
    for (const CLI::Option* opt : draw_only) {
      if (opt->count() > 0) throw CLI::ValidationError(opt->get_name(), "draws on the plot: give --plot PNG");
    }
  }
  if (o.x == "stress" && o.y == "stress") {
    throw CLI::ValidationError("--x", "--x stress with --y stress draws the stress against itself: use --y viscosity");
  }
  if (step->count() > 0 && data->count() == 0) throw CLI::ValidationError("--step", "only with --data");
}

void flow_curve_command(CLI::App& rheology) {
  auto* cmd = rheology.add_subcommand(
      "flow-curve",
      "steady flow curves tau(gamma_dot) with every branch (E11), written as CSV and/or plotted, optionally "
      "over measured data (--data)");
  auto o = std::make_shared<FlowCurveOpts>();
  o->params.add_to(cmd);
  cmd->add_option("--phi", o->phi,
                  "volume fraction(s), 0 < phi < phi_j (repeat for several); with --data: the volume fraction of "
                  "each --data file without a phi column (one per --data, as `rheology fit`)");
  cmd->add_option("--points", o->points, "points per curve (>= 2)")->capture_default_str();
  cmd->add_option("--out", o->out, "output CSV file (at least one of --out and --plot)");
  cmd->add_option("--plot", o->png, "plot the curves to this PNG (at least one of --out and --plot)");
  auto* data = cmd->add_option("--data", o->files,
                               "measured flow curves to draw as points over the model at their volume fractions: a "
                               "CSV with columns phi, shear_rate [1/s], shear_stress [Pa], or an instrument export "
                               "(TRIOS, RheoCompass, rSpace, CSV with units) followed by --phi, as `rheology fit "
                               "--kind curves` reads it; needs --plot");
  auto* step = cmd->add_option("--step", o->steps,
                               "the export's step, NAME or 1-based INDEX (after a --data for that file, before the "
                               "first --data for all; default: the one step with shear rate and stress)");
  auto* x = cmd->add_option("--x", o->x, "plot's horizontal axis: rate (shear rate) or stress (shear stress)")
                ->check(CLI::IsMember({"rate", "stress"}))
                ->capture_default_str();
  auto* y = cmd->add_option("--y", o->y, "plot's vertical axis: stress (shear stress) or viscosity (tau/gamma_dot)")
                ->check(CLI::IsMember({"stress", "viscosity"}))
                ->capture_default_str();
  auto* xlim = cmd->add_option("--xlim", o->xlim,
                               "plot's horizontal range LO,HI (default: the data's span with --data, else the "
                               "model's from 1e-2 to 1e4 tau*)");
  auto* ylim = cmd->add_option("--ylim", o->ylim, "plot's vertical range LO,HI (default: as --xlim)");
  cmd->callback([o, cmd, data, step, x, y, xlim, ylim] {
    // Usage first (exit 1): what to write, and options that only draw.
    check_flow_curve_usage(*o, {data, step, x, y, xlim, ylim}, data, step);
    const std::string xl = o->xlim.empty() ? "" : parse_limits(o->xlim, "--xlim");
    const std::string yl = o->ylim.empty() ? "" : parse_limits(o->ylim, "--ylim");
    if (o->files.empty() && o->phi.empty()) {
      throw CLI::ValidationError("--phi", "give the volume fraction(s) of the curves: --phi PHI (or --data FILE)");
    }

    const rheology::Preset p = o->params.load();
    if (o->points < 2) throw InputError(fmt::format("--points = {}: must be >= 2", o->points));
    FlowCurveData measured;
    std::vector<double> phis = o->phi;
    if (!o->files.empty()) {
      measured = read_flow_curve_data(*cmd, data, step, o->files, o->steps, o->phi, false);
      phis = measured_phis(measured.table);
    }
    for (double phi : phis) {
      rheology::validate_phi(p.steady, phi, fmt::format("--phi (parameters: {})", p.file));
    }
    if (!o->out.empty()) io::check_writable(o->out, "--out");
    if (!o->png.empty()) io::check_writable(o->png, "--plot");

    // The model's CSV: --out, or a temporary for the plot alone.
    namespace fs = std::filesystem;
    const fs::path tmp_dir = fs::temp_directory_path();
    const std::string stem = fmt::format("oobleck-flow-curve-{}", ::getpid());
    const std::string curves_csv = o->out.empty() ? (tmp_dir / (stem + "-model.csv")).string() : o->out;
    const std::string data_csv = (tmp_dir / (stem + "-data.csv")).string();
    TempFiles cleanup;
    if (o->out.empty()) cleanup.files.push_back(curves_csv);
    write_flow_curves(curves_csv, o->out.empty() ? "plot curves" : "--out", p, phis, o->points);
    if (!o->out.empty()) {
      fmt::print("wrote {} ({} curves x {} points; parameters {} [{} units])\n", o->out, phis.size(), o->points, p.name,
                 p.units);
    }
    if (!o->png.empty()) {
      std::vector<std::string> args = {
          curves_csv, "--title", fmt::format("{} ({} units)", p.name, p.units), "--x", o->x, "--y", o->y};
      if (p.units == "normalized") args.emplace_back("--normalized");
      if (!xl.empty()) args.insert(args.end(), {"--xlim", xl});
      if (!yl.empty()) args.insert(args.end(), {"--ylim", yl});
      if (!o->files.empty()) {
        cleanup.files.push_back(data_csv);
        write_plot_data(data_csv, measured.table);
        args.insert(args.end(), {"--data", data_csv, "--data-label", measured.table.file});
        fmt::print("data: {}: {} points at phi = {}\n", measured.table.file, measured.table.rows.size(),
                   fmt::join(phis, ", "));
      }
      plot("plot_flow_curves.py", args, o->png);
      fmt::print("wrote {}\n", o->png);
    }
  });
}

void dst_command(CLI::App& rheology) {
  auto* cmd = rheology.add_subcommand("dst", "the DST shear rate gamma_dot_DST (E14)");
  struct Opts {
    ParamsOption params;
    double phi = 0.0;
    bool json = false;
  };
  auto o = std::make_shared<Opts>();
  o->params.add_to(cmd);
  cmd->add_option("--phi", o->phi, "volume fraction")->required();
  cmd->add_flag("--json", o->json,
                "print one JSON object {\"phi\", \"shear_rate_dst\", \"max_shear_rate\", \"max_shear_rate_stress\"}");
  cmd->callback([o] {
    const rheology::Preset p = o->params.load();
    rheology::validate_phi(p.steady, o->phi, fmt::format("--phi (parameters: {})", p.file));
    std::string reason;
    const auto rate = rheology::shear_rate_dst(p.steady, o->phi, &reason);
    // The fastest steady shear of the whole flow curve (null: unbounded, CST).
    const auto fastest = rheology::fastest_steady_shear(p.steady, o->phi);
    if (o->json) {
      nlohmann::json j;
      j["phi"] = o->phi;
      j["shear_rate_dst"] = rate ? nlohmann::json(*rate) : nlohmann::json(nullptr);
      if (!rate) j["reason"] = reason;
      j["max_shear_rate"] = fastest ? nlohmann::json(fastest->shear_rate) : nlohmann::json(nullptr);
      j["max_shear_rate_stress"] =
          fastest && fastest->attained ? nlohmann::json(fastest->shear_stress) : nlohmann::json(nullptr);
      fmt::print("{}\n", j.dump());
      return;
    }
    if (rate) {
      fmt::print("gamma_dot_DST = {:.6g} 1/s  ({} at phi = {})\n", *rate, p.name, o->phi);
    } else {
      fmt::print("no DST at phi = {} for {}: {}\n", o->phi, p.name, reason);
    }
    if (!fastest) {
      fmt::print("fastest steady shear: unbounded (the flow curve rises without limit)\n");
    } else if (fastest->attained) {
      fmt::print(
          "fastest steady shear = {:.6g} 1/s at tau = {:.4g} Pa (the flow curve's peak); no steady flow is "
          "faster\n",
          fastest->shear_rate, fastest->shear_stress);
    } else {
      fmt::print("fastest steady shear = gamma_dot_DST, approached as the stress diverges; no steady flow is faster\n");
    }
  });
}

void structure_command(CLI::App& rheology) {
  auto* cmd = rheology.add_subcommand(
      "structure", "steady f(tau) of this model (eta_B -> infinity) beside Wyart–Cates and Singh et al.");
  struct Opts {
    ParamsOption params;
    int points = 200;
    std::string out, png;
  };
  auto o = std::make_shared<Opts>();
  o->params.add_to(cmd);
  cmd->add_option("--points", o->points, "number of stresses (log-spaced over 1e-3..1e3 tau*)")->capture_default_str();
  cmd->add_option("--out", o->out, "output CSV file")->required();
  cmd->add_option("--plot", o->png, "also plot to this PNG");
  cmd->callback([o] {
    const rheology::Preset p = o->params.load();
    if (o->points < 2) throw InputError(fmt::format("--points = {}: must be >= 2", o->points));
    io::check_writable(o->out, "--out");
    if (!o->png.empty()) io::check_writable(o->png, "--plot");
    io::OutputFile csv(o->out, "--out");
    csv.stream() << fmt::format("# units: stress={}, f_model=1, f_wyart_cates=1, f_singh=1; parameters {} ({} units)\n",
                                p.units == "normalized" ? "eta_0 gamma_dot_0" : "Pa", p.name, p.units);
    csv.stream() << "stress,f_model,f_wyart_cates,f_singh\n";
    const double ts = p.steady.tau_star;
    for (int k = 0; k < o->points; ++k) {
      const double tau = ts * std::pow(10.0, -3.0 + 6.0 * k / (o->points - 1));
      const double H = rheology::hardening(tau, ts);           // E7 with tau_bar ~ tau
      const double f_model = rheology::steady_f(H, 1.0, 1.0);  // E10, S = 1 (eta_B -> inf), f_m = 1
      csv.stream() << fmt::format("{},{},{},{}\n", num(tau), num(f_model), num(1.0 - std::exp(-tau / ts)),
                                  num(std::exp(-ts / tau)));
    }
    csv.commit();
    fmt::print("wrote {}\n", o->out);
    if (!o->png.empty()) {
      plot("plot_structure.py", {o->out, "--tau-star", num(ts), "--title", p.name}, o->png);
      fmt::print("wrote {}\n", o->png);
    }
  });
}

void volume_fraction_command(CLI::App& rheology) {
  auto* cmd = rheology.add_subcommand("volume-fraction", "phi from the mass fraction of swelling starch (E15)");
  auto in = std::make_shared<rheology::MassFractionInput>();
  auto json = std::make_shared<bool>(false);
  cmd->add_option("--mass-fraction", in->mass_fraction, "phi_W = m_cs/(m_cs + m_l)")->required();
  cmd->add_option("--rho-cs", in->rho_cs, "cornstarch grain density [kg/m^3]")->required();
  cmd->add_option("--rho-liquid", in->rho_liquid, "suspending liquid density [kg/m^3]")->required();
  cmd->add_option("--rho-water", in->rho_water, "water density [kg/m^3]")->required();
  cmd->add_option("--lambda", in->lambda, "pore-space correction")->capture_default_str();
  cmd->add_option("--beta", in->beta, "swelling correction")->capture_default_str();
  cmd->add_flag("--json", *json, "print a JSON object");
  cmd->callback([in, json] {
    rheology::validate_mass_fraction_input(*in);
    const double phi = rheology::volume_fraction(*in);
    if (*json) {
      fmt::print("{}\n", nlohmann::json{{"mass_fraction", in->mass_fraction}, {"phi", phi}}.dump());
    } else {
      fmt::print("phi = {:.6f}\n", phi);
    }
  });
}

/// One CSV field: quoted when it holds the separator, a quote, or spaces at its ends.
std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos && (s.empty() || (s.front() != ' ' && s.back() != ' '))) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

void import_command(CLI::App& rheology) {
  auto* cmd = rheology.add_subcommand(
      "import", "a rheometer's export (TA TRIOS .txt, Anton Paar RheoCompass, Malvern rSpace, CSV) as one CSV in SI");
  struct Opts {
    std::string file, out, step, format = "auto";
  };
  auto o = std::make_shared<Opts>();
  cmd->add_option("file", o->file, "the export file")->required();
  cmd->add_option("--out", o->out,
                  "CSV to write: step, step_name, time [s], shear_rate [1/s], shear_stress [Pa], viscosity [Pa s], "
                  "then the file's other columns (normalized names, SI)")
      ->required();
  cmd->add_option("--step", o->step,
                  "only this step: NAME (case-insensitive, TRIOS's ' - N' optional) or 1-based INDEX (default: all)");
  cmd->add_option("--format", o->format, "auto (from the content) | trios | rheocompass | rspace | csv")
      ->capture_default_str();
  cmd->callback([o] {
    const io::RheometerFormat format = io::parse_rheometer_format(o->format, "--format");
    io::check_writable(o->out, "--out");
    const io::RheometerFile f = io::read_rheometer(o->file, format);
    std::vector<std::size_t> steps;
    if (!o->step.empty()) steps = io::select_steps(f, o->step, "--step");
    const io::RheometerTable t = io::to_table(f, steps);
    io::OutputFile csv(o->out, "--out");
    auto& s = csv.stream();
    std::vector<std::string> names, units;
    for (const auto& c : t.columns) {
      names.push_back(csv_field(c.name));
      if (!c.si_unit.empty()) units.push_back(fmt::format("{}={}", c.name, c.si_unit));
    }
    s << fmt::format("# units: {}; read from {} ({})\n", fmt::join(units, ", "), o->file, io::to_string(f.format));
    s << fmt::format("{}\n", fmt::join(names, ","));
    for (std::size_t r = 0; r < t.rows; ++r) {
      std::string line;
      for (std::size_t j = 0; j < t.columns.size(); ++j) {
        const auto& c = t.columns[j];
        if (j) line += ',';
        if (c.is_text) {
          line += csv_field(c.text[r]);
        } else if (!std::isnan(c.values[r])) {
          line += fmt::format("{}", c.values[r]);  // the shortest text that reads back the same
        }
      }
      s << line << '\n';
    }
    csv.commit();
    std::vector<std::string> step_names;
    for (std::size_t k = 0; k < f.steps.size(); ++k) {
      const auto& st = f.steps[k];
      if (steps.empty() || std::find(steps.begin(), steps.end(), k) != steps.end())
        step_names.push_back(fmt::format("{} '{}' ({} rows)", st.index, st.name, st.rows()));
    }
    fmt::print("read {} ({}, {}): steps {}\n", o->file, io::to_string(f.format), f.encoding,
               fmt::join(step_names, ", "));
    fmt::print("wrote {} ({} rows x {} columns, SI)\n", o->out, t.rows, t.columns.size());
  });
}

}  // namespace

void add_rheology_commands(CLI::App& app) {
  auto* rheology = app.add_subcommand("rheology", "steady rheology: flow curves, DST, fitting");
  rheology->require_subcommand(1);
  flow_curve_command(*rheology);
  dst_command(*rheology);
  structure_command(*rheology);
  volume_fraction_command(*rheology);
  add_fit_command(*rheology);
  import_command(*rheology);
}

}  // namespace oobleck::cli
