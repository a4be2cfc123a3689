// `oobleck point ...`: the granular law (E16–E24, docs/granular.md) at one homogeneous material point:
// simple shear at fixed volume (rate- or stress-controlled) and relaxation after cessation of steady
// shear beside the SI's reduced ODE.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <initializer_list>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "cli_common.hpp"
#include "oobleck/core/error.hpp"
#include "oobleck/io/output_file.hpp"
#include "oobleck/material/point_driver.hpp"
#include "oobleck/rheology/flow_curve.hpp"

namespace oobleck::cli {
namespace {

/// Material overrides shared by the point commands; NaN means "keep the parameter set's value".
struct MaterialOverrides {
  double G = NAN, K = NAN, K0 = NAN, d = NAN, rho_s = NAN, mu_2 = NAN, b = NAN, K_3 = NAN, eta_0 = NAN;
  void add_to(CLI::App* cmd, bool with_G_K0 = true) {
    if (with_G_K0) {
      cmd->add_option("--G", G, "granular shear modulus [Pa] (E16)");
      cmd->add_option("--K0", K0, "rate factor of the structure evolution [-] (E24)");
    }
    cmd->add_option("--K", K, "granular bulk modulus [Pa] (E16)");
    cmd->add_option("--d", d, "grain diameter [m] (E19)");
    cmd->add_option("--rho-s", rho_s, "grain density [kg/m^3] (E19)");
    cmd->add_option("--mu2", mu_2, "inertial friction limit mu_2 >= mu_c [-] (E20)");
    cmd->add_option("--b", b, "inertial friction scale b >= 0 [-] (E20)");
    cmd->add_option("--K3", K_3, "dilatancy slope K_3 >= 0 [-] (E18)");
    cmd->add_option("--eta0", eta_0, "fluid viscosity [Pa s]");
  }
  void apply(rheology::Preset& p) const {
    auto positive = [](const char* opt, double v, const char* unit) {
      if (!std::isnan(v) && !(std::isfinite(v) && v > 0.0))
        throw InputError(fmt::format("{} = {}: must be a positive number [{}]", opt, v, unit));
      return !std::isnan(v);
    };
    auto nonneg = [](const char* opt, double v) {
      if (!std::isnan(v) && !(std::isfinite(v) && v >= 0.0))
        throw InputError(fmt::format("{} = {}: must be a finite number >= 0", opt, v));
      return !std::isnan(v);
    };
    if (positive("--G", G, "Pa")) p.granular.G = G;
    if (positive("--K", K, "Pa")) p.granular.K = K;
    if (positive("--K0", K0, "-")) p.granular.K_0 = K0;
    if (positive("--d", d, "m")) p.granular.d = d;
    if (positive("--rho-s", rho_s, "kg/m^3")) p.granular.rho_s = rho_s;
    if (positive("--eta0", eta_0, "Pa s")) p.steady.eta_0 = eta_0;
    if (nonneg("--b", b)) p.granular.b = b;
    if (nonneg("--K3", K_3)) p.granular.K_3 = K_3;
    if (!std::isnan(mu_2)) {
      if (!(std::isfinite(mu_2) && mu_2 >= p.steady.mu_c))
        throw InputError(fmt::format("--mu2 = {}: must be >= mu_c = {}", mu_2, p.steady.mu_c));
      p.granular.mu_2 = mu_2;
    }
    rheology::validate(p, "command line");
  }
};

/// A CSV's head for its columns, each with its SI unit (material::PointColumn; empty: a text
/// column): the comment line "# units: name=unit, ..." (text columns left out; a parameter set in
/// normalized units, the Singh presets, gives "normalized" for every dimensional column) and the
/// header line.
using CsvColumn = material::PointColumn;
std::string csv_head(std::span<const CsvColumn> columns, const rheology::Preset& p) {
  std::vector<std::string> units, names;
  for (const auto& c : columns) {
    names.emplace_back(c.name);
    if (c.unit.empty()) continue;
    units.push_back(fmt::format("{}={}", c.name, p.units == "normalized" && c.unit != "1" ? "normalized" : c.unit));
  }
  return fmt::format("# units: {}\n{}\n", fmt::join(units, ", "), fmt::join(names, ","));
}
std::string csv_head(std::initializer_list<CsvColumn> columns, const rheology::Preset& p) {
  return csv_head(std::span<const CsvColumn>(columns.begin(), columns.size()), p);
}

/// An option left at NaN (not given) as an empty optional.
std::optional<double> given(double v) { return std::isnan(v) ? std::nullopt : std::optional<double>(v); }

/// Progress line on stderr at most once per second.
class ProgressPrinter {
 public:
  explicit ProgressPrinter(std::string what) : what_(std::move(what)), last_(clock::now()) {}
  void operator()(double frac, const material::PointSample& s) {
    const auto now = clock::now();
    if (now - last_ < std::chrono::seconds(1)) return;
    last_ = now;
    fmt::print(stderr, "{}: {:5.1f}%  t = {:.4g} s, tau_bar = {:.4g} Pa, f = {:.4g}\n", what_, 100.0 * frac, s.time,
               s.granular_shear_stress, s.f);
    std::fflush(stderr);
  }

 private:
  using clock = std::chrono::steady_clock;
  std::string what_;
  clock::time_point last_;
};

void shear_command(CLI::App& point) {
  auto* cmd =
      point.add_subcommand("shear", "homogeneous simple shear at fixed volume (E16–E24), rate- or stress-controlled");
  struct Opts {
    ParamsOption params;
    MaterialOverrides mat;
    double phi = NAN, rate = NAN, stress = NAN, duration = NAN, dt = NAN, f0 = 0.0;
    int samples = 1000;
    std::string out, png;
  };
  auto o = std::make_shared<Opts>();
  o->params.add_to(cmd);
  o->mat.add_to(cmd);
  cmd->add_option("--phi", o->phi, "granular volume fraction (fixed)")->required();
  auto* r = cmd->add_option("--shear-rate", o->rate, "imposed shear rate [1/s]");
  auto* s = cmd->add_option("--shear-stress", o->stress,
                            "imposed mixture shear stress tau = tau_bar + eta_0 (1 + 5 phi/2) gamma_dot [Pa]");
  r->excludes(s);
  s->excludes(r);
  cmd->add_option("--duration", o->duration, "simulated time [s]")->required();
  cmd->add_option("--dt", o->dt, "time step [s] (default: resolves eta/G of the low-viscosity branch and 1e-3 strain)");
  cmd->add_option("--f0", o->f0, "initial structure f in [0, 1]")->capture_default_str();
  cmd->add_option("--samples", o->samples, "number of CSV rows (evenly spaced in time)")->capture_default_str();
  cmd->add_option("--out", o->out, "output CSV file")->required();
  cmd->add_option("--plot", o->png, "also plot stresses and f against strain to this PNG");
  cmd->callback([o] {
    rheology::Preset p = o->params.load();
    o->mat.apply(p);
    material::ShearInput in;
    in.phi = o->phi;
    in.shear_rate = given(o->rate);
    in.shear_stress = given(o->stress);
    in.duration = o->duration;
    in.dt = given(o->dt);
    in.f0 = o->f0;
    in.samples = o->samples;
    material::validate(in, material::ArgStyle::cli);
    io::check_writable(o->out, "--out");
    if (!o->png.empty()) io::check_writable(o->png, "--plot");
    const bool by_stress = in.shear_stress.has_value();

    const material::GranularLaw law(p);
    const material::ShearOptions so = material::shear_options(law, in);
    if (!in.dt) {
      fmt::print("dt = {:.4g} s (default{})\n", so.dt,
                 so.dt <= o->duration / 2e7 * (1.0 + 1e-12) ? "; floored at duration/2e7: eta/G is not resolved" : "");
    }
    ProgressPrinter progress("point shear");
    const auto res = material::run_shear(law, so, std::ref(progress));

    io::OutputFile csv(o->out, "--out");
    auto& st = csv.stream();
    st << csv_head({{"time", "s"},
                    {"strain", "1"},
                    {"shear_rate", "1/s"},
                    {"shear_stress", "Pa"},
                    {"granular_shear_stress", "Pa"},
                    {"granular_pressure", "Pa"},
                    {"sigma_xy", "Pa"},
                    {"f", "1"},
                    {"phi", "1"},
                    {"regime", ""},
                    {"gamma_dot_p", "1/s"},
                    {"I_v", "1"},
                    {"I_m", "1"},
                    {"beta", "1"},
                    {"mu_p", "1"},
                    {"phi_eq", "1"},
                    {"iterations", "1"}},
                   p);
    for (const auto& x : res.samples) {
      st << fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n", num(x.time), num(x.strain),
                        num(x.shear_rate), num(x.shear_stress), num(x.granular_shear_stress), num(x.granular_pressure),
                        num(x.sigma_xy), num(x.f), num(x.phi), material::regime_name(x.regime), num(x.gamma_dot_p),
                        num(x.I_v), num(x.I_m), num(x.beta), num(x.mu_p), num(x.phi_eq), x.iterations);
    }
    csv.commit();
    const auto& last = res.samples.back();
    fmt::print(
        "wrote {} ({} steps of {:.4g} s; final: shear rate {:.6g} 1/s, tau {:.6g} Pa, tau_bar {:.6g} Pa, "
        "p {:.6g} Pa, f {:.6g}, regime {})\n",
        o->out, res.steps, res.dt, last.shear_rate, last.shear_stress, last.granular_shear_stress,
        last.granular_pressure, last.f, material::regime_name(last.regime));
    if (!o->png.empty()) {
      const std::string title =
          fmt::format("{}, phi = {}, {}", p.name, o->phi,
                      by_stress ? fmt::format("tau = {} Pa", o->stress) : fmt::format("shear rate = {} 1/s", o->rate));
      plot("plot_point_shear.py", {o->out, "--title", title}, o->png);
      fmt::print("wrote {}\n", o->png);
    }
  });
}

void relax_command(CLI::App& point) {
  auto* cmd = point.add_subcommand(
      "relax", "stress relaxation after cessation of steady shear (SI: determining G and K_0), with the reduced ODE");
  struct Opts {
    ParamsOption params;
    MaterialOverrides mat;
    std::vector<double> G, K0;
    double phi = NAN, rate = NAN, stress = NAN, duration = NAN, dt = NAN;
    int samples = 200;
    std::string out, png;
  };
  auto o = std::make_shared<Opts>();
  o->params.add_to(cmd);
  o->mat.add_to(cmd, false);
  cmd->add_option("--G", o->G, "granular shear modulus/moduli [Pa] (repeat for several; default: parameter set)");
  cmd->add_option("--K0", o->K0, "structure rate factor(s) [-] (repeat for several; default: parameter set)");
  cmd->add_option("--phi", o->phi, "granular volume fraction (fixed)")->required();
  auto* r = cmd->add_option("--shear-rate", o->rate, "pre-shear rate [1/s]");
  auto* s = cmd->add_option("--shear-stress", o->stress, "pre-shear mixture shear stress [Pa] (stress-controlled)");
  r->excludes(s);
  s->excludes(r);
  cmd->add_option("--duration", o->duration, "relaxation time after cessation [s]")->required();
  cmd->add_option("--dt", o->dt,
                  "first relaxation step [s] (default: 1/20 of c(f_0) eta_0/G); later dt = max(dt, t/50)");
  cmd->add_option("--samples", o->samples, "CSV rows per case (log-spaced in time)")->capture_default_str();
  cmd->add_option("--out", o->out, "output CSV file")->required();
  cmd->add_option("--plot", o->png, "also plot tau_bar(t)/tau_bar_0 and f(t) with the reduced ODE to this PNG");
  cmd->callback([o] {
    rheology::Preset base = o->params.load();
    o->mat.apply(base);
    material::RelaxInput in;
    in.phi = o->phi;
    in.shear_rate = given(o->rate);
    in.shear_stress = given(o->stress);
    in.duration = o->duration;
    in.dt = given(o->dt);
    in.samples = o->samples;
    in.G = o->G;
    in.K_0 = o->K0;
    material::validate(in, base.steady, material::ArgStyle::cli);
    io::check_writable(o->out, "--out");
    if (!o->png.empty()) io::check_writable(o->png, "--plot");
    const bool by_stress = in.shear_stress.has_value();

    material::RelaxSweepHooks hooks;
    hooks.start = [](const material::RelaxCase& c) -> material::Progress {
      return ProgressPrinter(fmt::format("point relax G = {:g} Pa, K_0 = {:g}", c.G, c.K_0));
    };
    hooks.done = [](const material::RelaxCase& c, const material::RelaxResult& rr) {
      fmt::print(
          "G = {:g} Pa, K_0 = {:g}: steady tau_bar_0 = {:.6g} Pa, p_0 = {:.6g} Pa, f_0 = {:.6g} after {:.4g} "
          "strain; initial relaxation time c(f_0) eta_0/G = {:.4g} s; tau_bar(end)/tau_bar_0 = {:.4g}\n",
          c.G, c.K_0, rr.tau_bar_0, rr.p_0, rr.f_0, rr.preshear_strain, rr.relaxation_time_0,
          rr.samples.back().tau_bar / rr.tau_bar_0);
    };
    const std::vector<material::RelaxResult> results = material::run_relax_sweep(base, in, hooks);
    io::OutputFile csv(o->out, "--out");
    auto& st = csv.stream();
    st << csv_head(material::relax_columns(), base);
    for (std::size_t c = 0; c < results.size(); ++c) {
      for (const auto& x : results[c].samples) {
        const auto row = material::relax_row(c, results[c], x);
        std::vector<std::string> cells;
        for (std::size_t k = 0; k < row.size(); ++k)
          cells.push_back(material::relax_columns()[k].unit.empty() ? std::string(material::regime_name(x.regime))
                                                                    : num(row[k]));
        st << fmt::format("{}\n", fmt::join(cells, ","));
      }
    }
    csv.commit();
    fmt::print("wrote {} ({} cases)\n", o->out, results.size());
    if (!o->png.empty()) {
      const std::string title =
          fmt::format("{}, phi = {}, pre-shear {}", base.name, o->phi,
                      by_stress ? fmt::format("tau = {} Pa", o->stress) : fmt::format("{} 1/s", o->rate));
      plot("plot_point_relax.py", {o->out, "--title", title}, o->png);
      fmt::print("wrote {}\n", o->png);
    }
  });
}

}  // namespace

void add_point_commands(CLI::App& app) {
  auto* point = app.add_subcommand("point", "the granular law at one homogeneous material point (E16–E24)");
  point->require_subcommand(1);
  shear_command(*point);
  relax_command(*point);
}

}  // namespace oobleck::cli
