#include "oobleck/run/runner.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>
#include <memory>

#include <fmt/format.h>

#include "oobleck/analysis/annular.hpp"
#include "oobleck/analysis/fronts.hpp"
#include "oobleck/analysis/rod.hpp"
#include "oobleck/analysis/wheel.hpp"
#include "oobleck/analysis/summary_json.hpp"
#include "oobleck/core/build_info.hpp"
#include "oobleck/core/error.hpp"
#include "oobleck/io/checkpoint.hpp"
#include "oobleck/io/frames.hpp"
#include "oobleck/io/output_file.hpp"
#include "oobleck/io/progress.hpp"
#include "oobleck/io/series.hpp"
#include "oobleck/io/summary.hpp"
#include "oobleck/material/drag.hpp"
#include "oobleck/material/granular.hpp"
#include "oobleck/mpm/granular_body_law.hpp"
#include "oobleck/mpm/initial_state.hpp"
#include "oobleck/mpm/laws.hpp"
#include "oobleck/mpm/solver.hpp"
#include "oobleck/rheology/f_max.hpp"
#include "oobleck/rheology/flow_curve.hpp"
#include "oobleck/run/finite_check.hpp"
#include "oobleck/run/third_bodies.hpp"

namespace oobleck::run {

std::string checkpoint_path(const std::string& run_dir) { return run_dir + "/checkpoint.h5"; }
std::string stored_scene_path(const std::string& run_dir) { return run_dir + "/scene.toml"; }

namespace {

using scene::BoundaryType;
using scene::SceneConfig;
namespace fs = std::filesystem;

/// View a vector of fixed-size Eigen objects as doubles (they are stored without padding).
template <class T>
std::span<double> as_doubles(std::vector<T>& v) {
  static_assert(sizeof(T) == sizeof(double) * T::SizeAtCompileTime, "padded Eigen type");
  return {reinterpret_cast<double*>(v.data()), v.size() * static_cast<std::size_t>(T::SizeAtCompileTime)};
}
template <class T>
std::span<const double> as_doubles(const std::vector<T>& v) {
  static_assert(sizeof(T) == sizeof(double) * T::SizeAtCompileTime, "padded Eigen type");
  return {reinterpret_cast<const double*>(v.data()), v.size() * static_cast<std::size_t>(T::SizeAtCompileTime)};
}

template <class G>
class SceneRun {
 public:
  static constexpr int D = G::dim;
  static constexpr int NC = G::ncomp;
  using Vd = mpm::Vec<D>;
  using Vn = mpm::Vec<NC>;

  SceneRun(const SceneConfig& cfg, const RunOptions& opt) : cfg_(cfg), opt_(opt) { build(); }

  nlohmann::json run();

 private:
  void build();
  void fill_regions();
  void write_frame(io::FrameWriter& frames);
  std::vector<std::string> series_columns() const;
  std::vector<double> series_row() const;
  void write_checkpoint() const;
  void restore(const io::Checkpoint& cp);
  /// Call f(name, array) for every per-point array of the bodies and laws that a restart needs
  /// (the one list that write_checkpoint stores and restore reads back).
  template <class F>
  void for_each_point_array(F&& f) const;
  void check_finite() const;
  void sample_analysis();
  nlohmann::json parameters() const;
  nlohmann::json analysis_result() const;
  long steps_between(double interval_s, long fallback) const {
    return interval_s > 0 ? std::max(1L, static_cast<long>(std::llround(interval_s / dt_))) : fallback;
  }

  const SceneConfig& cfg_;
  RunOptions opt_;
  std::unique_ptr<mpm::Solver<G>> solver_;
  int grains_ = -1, fluid_ = -1;
  mpm::GranularBodyLaw<G>* granular_law_ = nullptr;
  mpm::FluidLaw<G>* fluid_law_ = nullptr;
  double dt_ = 0.0;
  long total_steps_ = 0;
  // settling analysis accumulators
  double settle_sum_ = 0.0;
  long settle_samples_ = 0;
  // annular analysis: nodal mixture v_theta samples
  std::vector<analysis::ShearFrame> shear_frames_;
  void sample_shear_frame();
  analysis::AnnularGeometry annular_geometry() const;

  // [[body]] entries (third_bodies.hpp)
  struct ThirdBody {
    int body = -1, pair = -1, motor = -1;
    const scene::BodyConfig* cfg = nullptr;
  };
  std::vector<ThirdBody> third_;
  int analysed_ = -1;  ///< index into third_ of the analysed body (intrusion, rod, wheel)
  /// Samples of the analysed body: time, centre of mass, mean velocity, mean contact force over
  /// the interval since the previous sample (impulse / time), extreme coordinate along the last
  /// axis (bottom for rod and intruder), motor ω and torque.
  struct TrackSample {
    double t = 0.0, bottom = 0.0, omega = 0.0, torque = 0.0;
    Vd centre = Vd::Zero();
    Vn velocity = Vn::Zero(), force = Vn::Zero();
  };
  std::vector<TrackSample> track_;
  Vn track_impulse_ = Vn::Zero();  ///< impulse sum at the previous sample
  double track_time_ = 0.0;        ///< time of the previous sample
  std::vector<analysis::IntrusionFrame> uz_frames_, f_frames_;  ///< intrusion field samples
  std::vector<Vd> x0_grains_;      ///< initial grain positions (displacement snapshots)
  std::size_t next_snapshot_ = 0;
  std::vector<std::string> snapshot_files_;
  nlohmann::json rod_profile_;  ///< |dz| vs depth below the rod at the first snapshot (not checkpointed)
  /// Wheel: point-to-point scatter of the granular pressure under the wheel at each frame (the
  /// SI's ringing figure; analysis::pressure_scatter).
  struct ScatterSample {
    double t = 0.0;
    analysis::PressureScatter s;
  };
  std::vector<ScatterSample> pressure_scatter_;
  double wheel_radius(const ThirdBody& tb) const {
    return tb.cfg->shape == scene::BodyShape::Disc ? tb.cfg->radius_m : tb.cfg->hub_radius_m + tb.cfg->paddle_length_m;
  }
  analysis::ScatterWindow scatter_window(const ThirdBody& tb) const;
  void sample_pressure_scatter();
  void build_bodies();
  void sample_track();
  void sample_intrusion_fields();
  void write_due_snapshots(bool final_step);
  nlohmann::json body_analysis() const;
  double bed_surface() const;
};

template <class G>
void SceneRun<G>::build() {
  const auto& gc = cfg_.grid;
  Vd origin;
  std::array<int, D> cells{};
  std::array<bool, D> periodic{};
  for (int a = 0; a < D; ++a) {
    origin[a] = gc.origin_m[a];
    cells[a] = gc.cells[a];
    periodic[a] = cfg_.boundary[2 * a].type == BoundaryType::Periodic;
  }
  mpm::Grid<D> grid(origin, gc.cell_size_m, cells, periodic);

  mpm::SolverOptions<G> so;
  so.dt_s = 1.0;  // set below, once the bodies exist
  switch (gc.shape) {
    case scene::ShapeKind::Linear: so.shape = mpm::ShapeKind::Linear; break;
    case scene::ShapeKind::Quadratic: so.shape = mpm::ShapeKind::QuadraticBSpline; break;
    case scene::ShapeKind::Cubic: so.shape = mpm::ShapeKind::CubicBSpline; break;
    case scene::ShapeKind::UGimp: so.shape = mpm::ShapeKind::UGimp; break;
  }
  so.gimp_half_width_cells = 0.5 / cfg_.regions.front().points_per_cell;
  so.transfer = cfg_.transfer.scheme == scene::TransferScheme::Apic ? mpm::Transfer::Apic : mpm::Transfer::FlipPicBlend;
  so.flip_fraction = cfg_.transfer.flip_fraction;
  so.gravity_m_s2 = Vn::Zero();
  for (int a = 0; a < D; ++a) so.gravity_m_s2[a] = cfg_.gravity_m_s2[a];
  so.threads = opt_.threads;
  so.mixture.rho_s_kg_m3 = cfg_.material.granular.rho_s;
  so.mixture.rho_f0_kg_m3 = cfg_.fluid.rho_f0_kg_m3;
  so.mixture.min_porosity = cfg_.coupling.porosity_min;
  so.mixture.drag.law = cfg_.coupling.drag == scene::DragLaw::Beetstra ? material::DragLaw::Beetstra
                                                                       : material::DragLaw::CarmanKozeny;
  so.mixture.drag.d_m = cfg_.material.granular.d;
  so.mixture.drag.eta_0_Pa_s = cfg_.fluid.eta_0_Pa_s;
  solver_ = std::make_unique<mpm::Solver<G>>(grid, so);

  for (int face = 0; face < 2 * D; ++face) {
    const scene::BoundaryConfig& b = cfg_.boundary[face];
    mpm::FaceCondition& fc = solver_->boundaries()[face];
    switch (b.type) {
      case BoundaryType::NoSlip: fc.type = mpm::WallType::NoSlip; break;
      case BoundaryType::Slip: fc.type = mpm::WallType::Slip; break;
      case BoundaryType::Friction:
        fc.type = mpm::WallType::Friction;
        fc.friction_coefficient = b.friction;
        break;
      case BoundaryType::Velocity:
        fc.type = mpm::WallType::Prescribed;
        fc.velocity_m_s = Eigen::Vector3d(b.velocity_m_s[0], b.velocity_m_s[1], b.velocity_m_s[2]);
        break;
      case BoundaryType::Axis: fc.type = mpm::WallType::Axis; break;
      case BoundaryType::Open:
      case BoundaryType::Periodic: fc.type = mpm::WallType::Open; break;
    }
  }
  fill_regions();
  build_bodies();

  if (cfg_.time.dt_s) {
    dt_ = *cfg_.time.dt_s;
    solver_->options().dt_s = dt_;
    try {
      solver_->check_time_step(1.0);
    } catch (const InputError& e) {
      throw InputError(fmt::format("{}: key 'time.dt' = {}: {}", cfg_.file, dt_, e.what()));
    }
  } else {
    dt_ = solver_->stable_dt(cfg_.time.cfl);
    if (!std::isfinite(dt_)) {
      throw InputError(fmt::format("{}: no stable time step could be derived (no material with a wave speed); "
                                   "set time.dt", cfg_.file));
    }
    solver_->options().dt_s = dt_;
  }
  total_steps_ = std::max(1L, static_cast<long>(std::llround(cfg_.time.duration_s / dt_)));
}

template <class G>
void SceneRun<G>::fill_regions() {
  const double h = cfg_.grid.cell_size_m;
  const double rho_s = cfg_.material.granular.rho_s;
  const double rho_f = cfg_.fluid.rho_f0_kg_m3;
  auto ensure_grains = [&]() -> mpm::Body<G>& {
    if (grains_ < 0) {
      grains_ = solver_->body_count();
      auto& b = solver_->add_body("grains", mpm::Phase::Grains);
      auto law = std::make_unique<mpm::GranularBodyLaw<G>>(cfg_.material);
      granular_law_ = law.get();
      b.set_law(std::move(law));
    }
    return solver_->body(grains_);
  };
  auto ensure_fluid = [&]() -> mpm::Body<G>& {
    if (fluid_ < 0) {
      fluid_ = solver_->body_count();
      auto& b = solver_->add_body("fluid", mpm::Phase::Fluid);
      material::FluidParams fp;
      fp.eta_0_Pa_s = cfg_.fluid.eta_0_Pa_s;
      fp.kappa_Pa = cfg_.fluid.kappa_Pa;
      fp.rho_f0_kg_m3 = rho_f;
      auto law = std::make_unique<mpm::FluidLaw<G>>(fp, cfg_.coupling.porosity_min);
      fluid_law_ = law.get();
      b.set_law(std::move(law));
    }
    return solver_->body(fluid_);
  };

  double surface = -std::numeric_limits<double>::infinity();
  double phi_bed = 0.0;
  bool suspended = false;
  for (const auto& r : cfg_.regions) {
    Vd lo, hi;
    for (int a = 0; a < D; ++a) {
      lo[a] = r.min_m[a];
      hi[a] = r.max_m[a];
    }
    Vn v0;
    for (int c = 0; c < NC; ++c) v0[c] = r.velocity_m_s[c];
    auto velocity = [v0](const Vd&) { return v0; };
    switch (r.phase) {
      case scene::Phase::Mixture:
        mpm::fill_box(ensure_grains(), lo, hi, h, r.points_per_cell, r.phi * rho_s, velocity);
        mpm::fill_box(ensure_fluid(), lo, hi, h, r.points_per_cell, (1.0 - r.phi) * rho_f, velocity);
        break;
      case scene::Phase::Grains:
        mpm::fill_box(ensure_grains(), lo, hi, h, r.points_per_cell, r.phi * rho_s, velocity);
        break;
      case scene::Phase::Fluid:
        mpm::fill_box(ensure_fluid(), lo, hi, h, r.points_per_cell, rho_f, velocity);
        break;
      case scene::Phase::Elastic: {
        auto& b = solver_->add_body(r.name, mpm::Phase::Solid);
        material::LinearElasticParams ep;
        ep.youngs_modulus_Pa = r.elastic.youngs_modulus_Pa;
        ep.poisson_ratio = r.elastic.poisson_ratio;
        b.set_law(std::make_unique<mpm::LinearElasticLaw<G>>(ep));
        mpm::fill_box(b, lo, hi, h, r.points_per_cell, r.elastic.density_kg_m3, velocity);
        break;
      }
    }
    if (r.initial_state != scene::InitialState::AtRest) {
      surface = std::max(surface, r.max_m[D - 1]);
      phi_bed = r.phi;
      suspended = r.initial_state == scene::InitialState::Suspended;
    }
  }
  for (int b = 0; b < solver_->body_count(); ++b) {
    if (solver_->body(b).size() == 0) {
      throw InputError(fmt::format("{}: body '{}' got no material points: regions must span at least one "
                                   "point spacing (cell_size/points_per_cell)", cfg_.file, solver_->body(b).name));
    }
  }
  if (std::isfinite(surface) && suspended) {
    // Grains out of contact: the fluid pressure carries the whole mixture weight,
    // p_f = rho_mix g depth with rho_mix = phi rho_s + (1 - phi) rho_f (E26: ln J = -p_f/kappa),
    // and the granular stress is zero.
    const double g = -cfg_.gravity_m_s2[D - 1];
    const double rho_mix = phi_bed * rho_s + (1.0 - phi_bed) * rho_f;
    if (fluid_ >= 0) {
      auto& fl = solver_->body(fluid_);
      for (std::int64_t p = 0; p < fl.size(); ++p) {
        const double pf = rho_mix * g * std::max(surface - fl.x_m[p][D - 1], 0.0);
        const double ln_J = -pf / cfg_.fluid.kappa_Pa;
        fluid_law_->ln_J[p] = ln_J;
        fl.mass_kg[p] /= std::exp(ln_J);
        fl.stress_Pa[p] = -pf * mpm::Mat3::Identity();
        fl.phi[p] = phi_bed;
      }
    }
  } else if (std::isfinite(surface)) {
    mpm::HydrostaticBed bed;
    bed.surface_m = surface;
    bed.g_m_s2 = -cfg_.gravity_m_s2[D - 1];
    bed.rho_s_kg_m3 = rho_s;
    bed.rho_f0_kg_m3 = rho_f;
    const double K = cfg_.material.granular.K, Gm = cfg_.material.granular.G;
    const double nu = (3 * K - 2 * Gm) / (2 * (3 * K + Gm));
    bed.K0 = nu / (1 - nu);  // uniaxial-strain elastic skeleton
    bed.phi_bed = phi_bed;
    mpm::set_hydrostatic_bed<G>(bed, grains_ >= 0 ? &solver_->body(grains_) : nullptr,
                                fluid_ >= 0 ? &solver_->body(fluid_) : nullptr);
  }
}

template <class G>
void SceneRun<G>::build_bodies() {
  for (const auto& bc : cfg_.bodies) {
    ThirdBody tb;
    tb.cfg = &bc;
    const int motors_before = bc.motor_omega_rad_s ? 1 : 0;
    std::tie(tb.body, tb.pair) = add_third_body<G>(*solver_, bc, cfg_.grid.cell_size_m, cfg_.file);
    if (motors_before) {
      int m = 0;
      for (const auto& other : third_) m += other.motor >= 0 ? 1 : 0;
      tb.motor = m;
    }
    if (bc.name == cfg_.analysis.body) analysed_ = static_cast<int>(third_.size());
    third_.push_back(tb);
  }
  if (grains_ >= 0) x0_grains_ = solver_->body(grains_).x_m;
}

template <class G>
double SceneRun<G>::bed_surface() const {
  double top = -INFINITY;
  for (const auto& r : cfg_.regions)
    if (r.phase != scene::Phase::Elastic) top = std::max(top, r.max_m[D - 1]);
  return top;
}

template <class G>
void SceneRun<G>::sample_track() {
  if (analysed_ < 0) return;
  const ThirdBody& tb = third_[static_cast<std::size_t>(analysed_)];
  const auto& body = solver_->body(tb.body);
  TrackSample s;
  s.t = solver_->time_s();
  s.centre = centre_of_mass(body, solver_->grid());
  s.velocity = body.total_momentum() / body.total_mass();
  s.bottom = INFINITY;
  for (const auto& x : body.x_m) s.bottom = std::min(s.bottom, x[D - 1]);
  const Vn J = solver_->contact(tb.pair).impulse_sum_N_s;
  s.force = s.t > track_time_ ? Vn((J - track_impulse_) / (s.t - track_time_)) : Vn(solver_->contact(tb.pair).force_N);
  track_impulse_ = J;
  track_time_ = s.t;
  if constexpr (std::is_same_v<G, mpm::PlaneStrain>) {
    if (tb.motor >= 0) {
      s.omega = solver_->motor(tb.motor).omega_measured_rad_s;
      s.torque = solver_->motor(tb.motor).torque_N_m;
    }
  }
  track_.push_back(s);
}

template <class G>
void SceneRun<G>::sample_intrusion_fields() {
  if constexpr (D == 2) {
    if (cfg_.analysis.kind != scene::AnalysisKind::Intrusion || analysed_ < 0) return;
    std::vector<const mpm::Body<G>*> mix;
    for (int b : {grains_, fluid_})
      if (b >= 0) mix.push_back(&solver_->body(b));
    const auto& tb = third_[static_cast<std::size_t>(analysed_)];
    double tip = INFINITY;
    for (const auto& x : solver_->body(tb.body).x_m) tip = std::min(tip, x[1]);
    tip -= 0.5 * cfg_.grid.cell_size_m / tb.cfg->points_per_cell;  // the flat end, not the lowest point
    analysis::IntrusionFrame uz;
    uz.time_s = solver_->time_s();
    uz.tip_z_m = tip;
    uz.field = nodal_average<G>(solver_->grid(), mix, [&](std::size_t b, std::int64_t p) { return mix[b]->v_m_s[p][1]; });
    uz_frames_.push_back(std::move(uz));
    if (grains_ >= 0 && granular_law_) {
      analysis::IntrusionFrame ff;
      ff.time_s = solver_->time_s();
      ff.tip_z_m = tip;
      ff.field = nodal_average<G>(solver_->grid(), {&solver_->body(grains_)},
                                  [&](std::size_t, std::int64_t p) { return granular_law_->f[static_cast<std::size_t>(p)]; });
      f_frames_.push_back(std::move(ff));
    }
  }
}

template <class G>
analysis::ScatterWindow SceneRun<G>::scatter_window(const ThirdBody& tb) const {
  // Under the wheel: two radii either side of its centre of mass, from three radii below it to
  // one above, on the grid's cells.
  const auto& grid = solver_->grid();
  const Vd c = centre_of_mass(solver_->body(tb.body), grid);
  const double R = wheel_radius(tb);
  analysis::ScatterWindow w;
  w.x_centre_m = c[0];
  w.half_width_m = 2.0 * R;
  w.y_min_m = c[D - 1] - 3.0 * R;
  w.y_max_m = c[D - 1] + R;
  w.origin_x_m = grid.origin_m[0];
  w.origin_y_m = grid.origin_m[D - 1];
  w.cell_m = grid.h_m;
  w.period_m = cfg_.boundary[0].type == scene::BoundaryType::Periodic ? cfg_.grid.size_m[0] : 0.0;
  return w;
}

template <class G>
void SceneRun<G>::sample_pressure_scatter() {
  if (cfg_.analysis.kind != scene::AnalysisKind::Wheel || analysed_ < 0 || grains_ < 0) return;
  // SI figure: how smooth the point pressure p~ = -tr(sigma)/3 of the grains is under the wheel.
  const auto& gb = solver_->body(grains_);
  std::vector<double> px, py, pp;
  for (std::int64_t p = 0; p < gb.size(); ++p) {
    px.push_back(gb.x_m[p][0]);
    py.push_back(gb.x_m[p][1]);
    pp.push_back(-gb.stress_Pa[p].trace() / 3.0);
  }
  const auto r = analysis::pressure_scatter(px, py, pp, scatter_window(third_[static_cast<std::size_t>(analysed_)]));
  if (r.points > 0) pressure_scatter_.push_back({solver_->time_s(), r});  // else no grains under the wheel
}

template <class G>
void SceneRun<G>::write_due_snapshots(bool final_step) {
  if constexpr (D == 2) {
    const auto& times = cfg_.analysis.snapshot_times_s;
    // Times after the run's end (a shortened run, --set time.duration) are skipped; the last step
    // takes a time within half a step of the end (duration = round(duration/dt) steps).
    while (next_snapshot_ < times.size() &&
           (solver_->time_s() >= times[next_snapshot_] - 0.5 * dt_ ||
            (final_step && times[next_snapshot_] <= cfg_.time.duration_s))) {
      // Nodal fields (bilinear, mass-weighted; docs/output.md "Snapshots"): mixture velocity,
      // grain displacement since t = 0, structure f, granular pressure p~, volume fraction phi
      // (1 - nodal porosity of the step).
      std::vector<const mpm::Body<G>*> mix;
      for (int b : {grains_, fluid_})
        if (b >= 0) mix.push_back(&solver_->body(b));
      const auto& grid = solver_->grid();
      auto vel = [&](int c) {
        return nodal_average<G>(grid, mix, [&](std::size_t b, std::int64_t p) { return mix[b]->v_m_s[p][c]; });
      };
      const auto ux = vel(0), uy = vel(1);
      analysis::GridField2D dx = ux, dy = ux, f = ux, pg = ux;
      if (grains_ >= 0) {
        const auto& gb = solver_->body(grains_);
        const std::vector<const mpm::Body<G>*> gs = {&gb};
        dx = nodal_average<G>(grid, gs, [&](std::size_t, std::int64_t p) {
          return mpm::periodic_difference<2>(grid, gb.x_m[p], x0_grains_[static_cast<std::size_t>(p)])[0];
        });
        dy = nodal_average<G>(grid, gs, [&](std::size_t, std::int64_t p) {
          return mpm::periodic_difference<2>(grid, gb.x_m[p], x0_grains_[static_cast<std::size_t>(p)])[1];
        });
        f = nodal_average<G>(grid, gs, [&](std::size_t, std::int64_t p) { return granular_law_->f[static_cast<std::size_t>(p)]; });
        pg = nodal_average<G>(grid, gs, [&](std::size_t, std::int64_t p) { return -gb.stress_Pa[p].trace() / 3.0; });
      } else {
        std::fill(dx.values.begin(), dx.values.end(), 0.0);
        dy = f = pg = dx;
      }
      const auto& n_nodal = solver_->nodal_porosity();
      std::string text = "x,y,u_x,u_y,displacement_x,displacement_y,f,p_grains,phi\n";
      for (std::size_t j = 0; j < ux.ny; ++j) {
        for (std::size_t i = 0; i < ux.nx; ++i) {
          const std::size_t k = j * ux.nx + i;
          double phi = 0.0;
          if (!n_nodal.empty()) {
            const int flat = grid.storage_index(0, static_cast<int>(i)) * grid.stride(0) +
                             grid.storage_index(1, static_cast<int>(j)) * grid.stride(1);
            phi = 1.0 - n_nodal[static_cast<std::size_t>(flat)];
          }
          text += fmt::format("{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g}\n", ux.x(i), ux.y(j),
                              ux.values[k], uy.values[k], dx.values[k], dy.values[k], f.values[k], pg.values[k], phi);
        }
      }
      const std::string name = fmt::format("snapshot_{}.csv", next_snapshot_);
      io::write_file_atomically(opt_.out_dir + "/" + name,
                                fmt::format("# t = {:.9g} s (requested {:.9g} s), step {}\n", solver_->time_s(),
                                            times[next_snapshot_], solver_->steps()) + text,
                                "snapshot");
      snapshot_files_.push_back(name);
      if (cfg_.analysis.kind == scene::AnalysisKind::Rod && analysed_ >= 0 && rod_profile_.is_null()) {
        // Fig. 7c: |dz| vs depth on the axis below the rod's tip at the first snapshot.
        const auto& tb = third_[static_cast<std::size_t>(analysed_)];
        double tip = INFINITY;
        for (const auto& x : solver_->body(tb.body).x_m) tip = std::min(tip, x[1]);
        tip -= 0.5 * cfg_.grid.cell_size_m / tb.cfg->points_per_cell;
        try {
          const auto prof = analysis::displacement_below_rod(dy, tip, bed_surface(), -1.0, grid.origin_m[0],
                                                             grid.origin_m[1] + cfg_.grid.cell_size_m);
          rod_profile_ = analysis::to_json(prof);
          rod_profile_["time"] = solver_->time_s();
          rod_profile_["rod_tip"] = tip;
        } catch (const InputError& e) {
          rod_profile_ = {{"note", e.what()}};
        }
      }
      ++next_snapshot_;
    }
  } else {
    (void)final_step;
  }
}

template <class G>
void SceneRun<G>::check_finite() const {
  for (int b = 0; b < solver_->body_count(); ++b) {
    const auto& body = solver_->body(b);
    // The step's G2P and the body's law check what they write (x, v, V; the stress) as they write
    // it; scan the body only where one of them did not check or found a non-finite value.
    if (solver_->first_non_finite_kinematics(b) == mpm::kAllFinite && body.law &&
        body.law->first_non_finite_stress() == mpm::kAllFinite)
      continue;
    if (const auto bad = first_non_finite(body)) {
      throw NumericalError(fmt::format(
          "non-finite {} at step {} (t = {:.6g} s): body '{}' (law: {}), point {}; stopping before any output "
          "of this step is written",
          bad->what, solver_->steps(), solver_->time_s(), body.name, body.law ? body.law->name() : "none", bad->point));
    }
  }
}

template <class G>
void SceneRun<G>::write_frame(io::FrameWriter& frames) {
  io::Frame frame;
  frame.time = solver_->time_s();
  frame.step = solver_->steps();
  // Storage for the per-field arrays (the frame holds spans).
  std::vector<std::vector<double>> store;
  auto column = [&](std::size_t n) -> std::vector<double>& {
    store.emplace_back(n, 0.0);
    return store.back();
  };
  store.reserve(64 * static_cast<std::size_t>(solver_->body_count()) + 16);
  for (int b = 0; b < solver_->body_count(); ++b) {
    const auto& body = solver_->body(b);
    const auto n = static_cast<std::size_t>(body.size());
    std::array<std::vector<double>*, 3> pos{};
    for (int a = 0; a < D; ++a) {
      pos[a] = &column(n);
      for (std::size_t p = 0; p < n; ++p) (*pos[a])[p] = body.x_m[p][a];
    }
    io::PointCloud cloud = D == 2 ? io::PointCloud(body.name, {*pos[0], *pos[1]})
                                  : io::PointCloud(body.name, {*pos[0], *pos[1], *pos[2]});
    std::array<std::vector<double>*, 3> vel{};
    for (int c = 0; c < NC; ++c) {
      vel[c] = &column(n);
      for (std::size_t p = 0; p < n; ++p) (*vel[c])[p] = body.v_m_s[p][c];
    }
    if (NC == 2) cloud.vector("velocity", {*vel[0], *vel[1]});
    else cloud.vector("velocity", {*vel[0], *vel[1], *vel[2]});
    std::array<std::vector<double>*, 6> s6{};
    const int idx[6][2] = {{0, 0}, {0, 1}, {0, 2}, {1, 1}, {1, 2}, {2, 2}};
    for (int k = 0; k < 6; ++k) {
      s6[k] = &column(n);
      for (std::size_t p = 0; p < n; ++p) (*s6[k])[p] = body.stress_Pa[p](idx[k][0], idx[k][1]);
    }
    cloud.sym_tensor("stress", {*s6[0], *s6[1], *s6[2], *s6[3], *s6[4], *s6[5]});
    auto& pressure = column(n);
    for (std::size_t p = 0; p < n; ++p) pressure[p] = -body.stress_Pa[p].trace() / 3.0;
    cloud.scalar(b == fluid_ ? "fluid_pressure" : "pressure", pressure);
    cloud.scalar("mass", body.mass_kg).scalar("volume", body.volume_m3);
    if (b == grains_) {
      auto& phi = column(n);
      auto& tau = column(n);
      auto& regime = column(n);
      for (std::size_t p = 0; p < n; ++p) {
        phi[p] = granular_law_->phi_of(body, static_cast<std::int64_t>(p));
        tau[p] = material::tau_bar(body.stress_Pa[p]);
        regime[p] = granular_law_->regime[p];
      }
      cloud.scalar("f", granular_law_->f).scalar("phi", phi).scalar("tau_bar", tau);
      cloud.scalar("regime", regime).scalar("gamma_dot_p", granular_law_->gamma_dot_p);
    }
    if (b == fluid_) {
      auto& J = column(n);  // (the frames show J = ρ_f0/ρ_f; the law's state is ln J)
      for (std::size_t p = 0; p < n; ++p) J[p] = std::exp(fluid_law_->ln_J[p]);
      cloud.scalar("phi", body.phi).scalar("J", J);
    }
    frame.bodies.push_back(std::move(cloud));
  }
  // Nodal porosity on the physical nodes (x fastest), when there is a mixture.
  const auto& n_nodal = solver_->nodal_porosity();
  if (!n_nodal.empty()) {
    const auto& grid = solver_->grid();
    std::array<std::size_t, 3> nodes{1, 1, 1};
    for (int a = 0; a < D; ++a) nodes[a] = static_cast<std::size_t>(grid.periodic[a] ? grid.cells[a] : grid.cells[a] + 1);
    auto& values = column(nodes[0] * nodes[1] * nodes[2]);
    for (std::size_t k = 0; k < nodes[2]; ++k) {
      for (std::size_t j = 0; j < nodes[1]; ++j) {
        for (std::size_t i = 0; i < nodes[0]; ++i) {
          const int logical[3] = {static_cast<int>(i), static_cast<int>(j), static_cast<int>(k)};
          int flat = 0;
          for (int a = 0; a < D; ++a) flat += grid.storage_index(a, logical[a]) * grid.stride(a);
          values[i + nodes[0] * (j + nodes[1] * k)] = n_nodal[static_cast<std::size_t>(flat)];
        }
      }
    }
    std::array<double, 3> origin{0, 0, 0}, spacing{0, 0, 0};
    for (int a = 0; a < D; ++a) {
      origin[a] = grid.origin_m[a];
      spacing[a] = grid.h_m;
    }
    io::NodeGrid ng(D, origin, spacing, nodes);
    ng.scalar("porosity", values);
    frame.grid = std::move(ng);
  }
  frames.write(frame);
  sample_pressure_scatter();
}

template <class G>
std::vector<std::string> SceneRun<G>::series_columns() const {
  std::vector<std::string> c = {"time", "step"};
  for (int b = 0; b < solver_->body_count(); ++b) {
    const std::string& n = solver_->body(b).name;
    c.push_back("kinetic_energy_" + n);
    for (int k = 0; k < NC; ++k) c.push_back(fmt::format("momentum_{}_{}", n, k));
    c.push_back("mass_" + n);
    c.push_back("max_speed_" + n);
  }
  for (const auto& tb : third_) {
    const std::string& n = tb.cfg->name;
    for (int k = 0; k < D; ++k) c.push_back(fmt::format("centre_{}_{}", n, k));
    for (int k = 0; k < NC; ++k) c.push_back(fmt::format("contact_force_{}_{}", n, k));
    if (tb.motor >= 0) {
      c.push_back("omega_" + n);
      c.push_back("motor_torque_" + n);
    }
  }
  return c;
}

template <class G>
std::vector<double> SceneRun<G>::series_row() const {
  std::vector<double> r = {solver_->time_s(), static_cast<double>(solver_->steps())};
  for (int b = 0; b < solver_->body_count(); ++b) {
    const auto& body = solver_->body(b);
    r.push_back(body.kinetic_energy());
    const Vn P = body.total_momentum();
    for (int k = 0; k < NC; ++k) r.push_back(P[k]);
    r.push_back(body.total_mass());
    double vmax = 0.0;
    for (const auto& v : body.v_m_s) vmax = std::max(vmax, v.norm());
    r.push_back(vmax);
  }
  for (const auto& tb : third_) {
    const Vd c = centre_of_mass(solver_->body(tb.body), solver_->grid());
    for (int k = 0; k < D; ++k) r.push_back(c[k]);
    const Vn F = solver_->contact(tb.pair).force_N;
    for (int k = 0; k < NC; ++k) r.push_back(F[k]);
    if (tb.motor >= 0) {
      if constexpr (std::is_same_v<G, mpm::PlaneStrain>) {
        r.push_back(solver_->motor(tb.motor).omega_measured_rad_s);
        r.push_back(solver_->motor(tb.motor).torque_N_m);
      }
    }
  }
  return r;
}

template <class G>
template <class F>
void SceneRun<G>::for_each_point_array(F&& f) const {
  for (int b = 0; b < solver_->body_count(); ++b) {
    auto& body = solver_->body(b);
    const std::string p = fmt::format("body{}/", b);
    f(p + "mass", body.mass_kg);
    f(p + "volume", body.volume_m3);
    f(p + "volume0", body.volume0_m3);
    f(p + "x", as_doubles(body.x_m));
    f(p + "v", as_doubles(body.v_m_s));
    f(p + "C", as_doubles(body.C_1_s));
    f(p + "L", as_doubles(body.L_1_s));
    f(p + "stress", as_doubles(body.stress_Pa));
    f(p + "f_ext", as_doubles(body.f_ext_N));
    f(p + "phi", body.phi);
    f(p + "div_q", body.div_q_1_s);
  }
  if (granular_law_) {
    f("granular/f", granular_law_->f);
    f("granular/regime", granular_law_->regime);
    f("granular/gamma_dot_p", granular_law_->gamma_dot_p);
  }
  if (fluid_law_) f("fluid/ln_J", fluid_law_->ln_J);
}

template <class G>
void SceneRun<G>::write_checkpoint() const {
  io::CheckpointWriter cp(checkpoint_path(opt_.out_dir));
  cp.set_step(solver_->steps());
  cp.set_time(solver_->time_s());
  cp.set_config(cfg_.resolved_toml);
  cp.attribute("dt", dt_);
  cp.attribute("threads", static_cast<std::int64_t>(solver_->threads()));
  cp.attribute("settle_sum", settle_sum_);
  cp.attribute("settle_samples", static_cast<std::int64_t>(settle_samples_));
  for_each_point_array([&](const std::string& name, auto&& a) { cp.array(name, a); });
  for (std::size_t k = 0; k < third_.size(); ++k) {
    const auto& rm = solver_->rigid_motion(third_[k].body);
    cp.array(fmt::format("third{}/rigid_velocity", k), std::span<const double>(rm.velocity_m_s.data(), NC));
    const Vn J = solver_->contact(third_[k].pair).impulse_sum_N_s;
    cp.array(fmt::format("third{}/impulse_sum", k), std::span<const double>(J.data(), NC));
  }
  if (!x0_grains_.empty()) cp.array("analysis/x0_grains", as_doubles(x0_grains_));
  cp.attribute("next_snapshot", static_cast<std::int64_t>(next_snapshot_));
  if (!pressure_scatter_.empty()) {
    std::vector<double> flat;
    for (const auto& r : pressure_scatter_)
      flat.insert(flat.end(), {r.t, r.s.relative, r.s.rms_deviation_Pa, r.s.rms_Pa, static_cast<double>(r.s.points),
                               static_cast<double>(r.s.cells)});
    cp.array("analysis/pressure_scatter", flat);
  }
  // Sampled nodal fields of the annular and intrusion analyses (all on the grid's nodes).
  auto save_fields = [&](const std::string& name, const auto& frames, auto field_of) {
    if (frames.empty()) return;
    std::vector<double> times, values, tips;
    for (const auto& fr : frames) {
      times.push_back(fr.time_s);
      const auto& f = field_of(fr);
      values.insert(values.end(), f.values.begin(), f.values.end());
      if constexpr (requires { fr.tip_z_m; }) tips.push_back(fr.tip_z_m);
    }
    cp.array(name + "/time", times);
    cp.array(name + "/values", values);
    if (!tips.empty()) cp.array(name + "/tip_z", tips);
  };
  save_fields("analysis/shear", shear_frames_, [](const analysis::ShearFrame& f) -> const analysis::GridField2D& { return f.v_theta; });
  if (!shear_frames_.empty() && !shear_frames_.front().f.values.empty())
    save_fields("analysis/shear_f", shear_frames_, [](const analysis::ShearFrame& f) -> const analysis::GridField2D& { return f.f; });
  save_fields("analysis/uz", uz_frames_, [](const analysis::IntrusionFrame& f) -> const analysis::GridField2D& { return f.field; });
  save_fields("analysis/f", f_frames_, [](const analysis::IntrusionFrame& f) -> const analysis::GridField2D& { return f.field; });
  if (!track_.empty()) {
    std::vector<double> flat;
    for (const auto& t : track_) {
      flat.insert(flat.end(), {t.t, t.bottom, t.omega, t.torque});
      flat.insert(flat.end(), t.centre.data(), t.centre.data() + D);
      flat.insert(flat.end(), t.velocity.data(), t.velocity.data() + NC);
      flat.insert(flat.end(), t.force.data(), t.force.data() + NC);
    }
    cp.array("analysis/track", flat);
    cp.array("analysis/track_impulse", std::span<const double>(track_impulse_.data(), NC));
    cp.attribute("track_time", track_time_);
  }
  cp.commit();
}

template <class G>
void SceneRun<G>::restore(const io::Checkpoint& cp) {
  if (cp.real_attribute("dt") != dt_) {
    throw InputError(fmt::format("{}: time step {} s differs from the checkpoint's {} s", cp.file(), dt_,
                                 cp.real_attribute("dt")));
  }
  for_each_point_array([&](const std::string& name, auto&& a) {
    if constexpr (std::is_same_v<std::remove_cvref_t<decltype(a)>, std::vector<double>>) {
      if (name == "fluid/ln_J" && !cp.has(name) && cp.has("fluid/J")) {
        // A checkpoint of a version before the fluid's state became ln J: its J, in logarithms
        // (the continued run differs from an uninterrupted one by that logarithm's round-off).
        cp.read_into("fluid/J", a);
        for (double& x : a) x = std::log(x);
        return;
      }
    }
    cp.read_into(name, a);
  });
  for (std::size_t k = 0; k < third_.size(); ++k) {
    auto& rm = solver_->rigid_motion(third_[k].body);
    cp.read_into(fmt::format("third{}/rigid_velocity", k), std::span<double>(rm.velocity_m_s.data(), NC));
    Vn J;
    cp.read_into(fmt::format("third{}/impulse_sum", k), std::span<double>(J.data(), NC));
    solver_->set_contact_impulse_sum(third_[k].pair, J);
  }
  if (!x0_grains_.empty()) cp.read_into("analysis/x0_grains", as_doubles(x0_grains_));
  next_snapshot_ = static_cast<std::size_t>(cp.int_attribute("next_snapshot"));
  // Sampled fields: rebuilt on the grid of this run (same scene, so the same grid).
  auto load_fields = [&](const std::string& name, auto& frames, const analysis::GridField2D& shape, auto make) {
    if (!cp.has(name + "/time")) return;
    const auto& times = cp.doubles(name + "/time");
    const auto& values = cp.doubles(name + "/values");
    const std::size_t n = shape.nx * shape.ny;
    if (values.size() != n * times.size())
      throw InputError(fmt::format("{}: '{}' does not match this scene's grid", cp.file(), name));
    for (std::size_t k = 0; k < times.size(); ++k) {
      analysis::GridField2D f = shape;
      f.values.assign(values.begin() + static_cast<std::ptrdiff_t>(k * n), values.begin() + static_cast<std::ptrdiff_t>((k + 1) * n));
      frames.push_back(make(times[k], std::move(f), k));
    }
  };
  if constexpr (D == 2) {
    const auto& grid = solver_->grid();
    analysis::GridField2D shape;
    shape.origin_x = grid.origin_m[0];
    shape.origin_y = grid.origin_m[1];
    shape.h = grid.h_m;
    shape.nx = static_cast<std::size_t>(grid.periodic[0] ? grid.cells[0] : grid.cells[0] + 1);
    shape.ny = static_cast<std::size_t>(grid.periodic[1] ? grid.cells[1] : grid.cells[1] + 1);
    load_fields("analysis/shear", shear_frames_, shape, [](double t, analysis::GridField2D f, std::size_t) {
      analysis::ShearFrame fr;
      fr.time_s = t;
      fr.v_theta = std::move(f);
      return fr;
    });
    std::vector<analysis::GridField2D> shear_f;
    load_fields("analysis/shear_f", shear_f, shape, [](double, analysis::GridField2D f, std::size_t) { return f; });
    if (!shear_f.empty() && shear_f.size() != shear_frames_.size())
      throw InputError(fmt::format("{}: 'analysis/shear_f' has {} frames, 'analysis/shear' {}", cp.file(),
                                   shear_f.size(), shear_frames_.size()));
    for (std::size_t k = 0; k < shear_f.size(); ++k) shear_frames_[k].f = std::move(shear_f[k]);
    for (auto [name, frames] : {std::pair{"analysis/uz", &uz_frames_}, std::pair{"analysis/f", &f_frames_}}) {
      const std::vector<double> tips = cp.has(std::string(name) + "/tip_z") ? cp.doubles(std::string(name) + "/tip_z")
                                                                             : std::vector<double>{};
      load_fields(name, *frames, shape, [&](double t, analysis::GridField2D f, std::size_t k) {
        analysis::IntrusionFrame fr;
        fr.time_s = t;
        fr.tip_z_m = k < tips.size() ? tips[k] : 0.0;
        fr.field = std::move(f);
        return fr;
      });
    }
  }
  for (std::size_t k = 0; k < next_snapshot_; ++k) snapshot_files_.push_back(fmt::format("snapshot_{}.csv", k));
  if (cp.has("analysis/pressure_scatter")) {
    const auto& flat = cp.doubles("analysis/pressure_scatter");
    for (std::size_t o = 0; o + 6 <= flat.size(); o += 6) {
      ScatterSample r;
      r.t = flat[o];
      r.s.relative = flat[o + 1];
      r.s.rms_deviation_Pa = flat[o + 2];
      r.s.rms_Pa = flat[o + 3];
      r.s.points = static_cast<std::int64_t>(flat[o + 4]);
      r.s.cells = static_cast<std::int64_t>(flat[o + 5]);
      pressure_scatter_.push_back(r);
    }
  }
  if (cp.has("analysis/track")) {
    const auto& flat = cp.doubles("analysis/track");
    const std::size_t w = 4 + D + 2 * NC;
    for (std::size_t o = 0; o + w <= flat.size(); o += w) {
      TrackSample t;
      t.t = flat[o];
      t.bottom = flat[o + 1];
      t.omega = flat[o + 2];
      t.torque = flat[o + 3];
      for (int k = 0; k < D; ++k) t.centre[k] = flat[o + 4 + k];
      for (int k = 0; k < NC; ++k) t.velocity[k] = flat[o + 4 + D + k];
      for (int k = 0; k < NC; ++k) t.force[k] = flat[o + 4 + D + NC + k];
      track_.push_back(t);
    }
    cp.read_into("analysis/track_impulse", std::span<double>(track_impulse_.data(), NC));
    track_time_ = cp.real_attribute("track_time");
  }
  settle_sum_ = cp.real_attribute("settle_sum");
  settle_samples_ = static_cast<long>(cp.int_attribute("settle_samples"));
  solver_->set_clock(cp.time(), cp.step());
}

template <class G>
void SceneRun<G>::sample_analysis() {
  if (cfg_.analysis.kind != scene::AnalysisKind::Settling || grains_ < 0 || fluid_ < 0) return;
  if (solver_->time_s() < cfg_.analysis.average_from_s) return;
  // Mean vertical velocities of both phases in the middle half of the column, the mixture volume
  // flux j = phi v_s + (1 - phi) v_f there, and the settling velocity -(v_s - j), positive down.
  const auto& reg = cfg_.regions.front();
  const double z0 = reg.min_m[D - 1], z1 = reg.max_m[D - 1];
  const double lo = z0 + 0.25 * (z1 - z0), hi = z1 - 0.25 * (z1 - z0);
  auto mean_v = [&](const mpm::Body<G>& body, double& volume) {
    double mv = 0.0, m = 0.0;
    volume = 0.0;
    for (std::int64_t p = 0; p < body.size(); ++p) {
      if (body.x_m[p][D - 1] < lo || body.x_m[p][D - 1] > hi) continue;
      mv += body.mass_kg[p] * body.v_m_s[p][D - 1];
      m += body.mass_kg[p];
      volume += body.volume_m3[p];
    }
    return m > 0 ? mv / m : 0.0;
  };
  double vol_s = 0.0, vol_f = 0.0;
  const double vs = mean_v(solver_->body(grains_), vol_s);
  const double vf = mean_v(solver_->body(fluid_), vol_f);
  const double phi = reg.phi;
  const double j = phi * vs + (1.0 - phi) * vf;
  settle_sum_ += -(vs - j);
  ++settle_samples_;
}

template <class G>
analysis::AnnularGeometry SceneRun<G>::annular_geometry() const {
  analysis::AnnularGeometry g;
  g.bob_radius_m = cfg_.grid.origin_m[0];
  g.outer_radius_m = cfg_.grid.origin_m[0] + cfg_.grid.size_m[0];
  g.bob_speed_m_per_s = cfg_.boundary[0].velocity_m_s[2];
  double top = -INFINITY;
  for (const auto& r : cfg_.regions) top = std::max(top, r.max_m[D - 1]);
  g.sample_z_m = std::isfinite(cfg_.analysis.sample_z_m) ? cfg_.analysis.sample_z_m : top - 2.0 * cfg_.grid.cell_size_m;
  g.start_time_s = 0.0;
  return g;
}

template <class G>
void SceneRun<G>::sample_shear_frame() {
  if constexpr (NC == 3 && D == 2) {
    // Mass-weighted mixture v_theta on the physical nodes (r fastest).
    const auto& grid = solver_->grid();
    analysis::ShearFrame fr;
    fr.time_s = solver_->time_s();
    fr.v_theta.origin_x = grid.origin_m[0];
    fr.v_theta.origin_y = grid.origin_m[1];
    fr.v_theta.h = grid.h_m;
    fr.v_theta.nx = static_cast<std::size_t>(grid.cells[0] + 1);
    fr.v_theta.ny = static_cast<std::size_t>(grid.periodic[1] ? grid.cells[1] : grid.cells[1] + 1);
    fr.v_theta.values.assign(fr.v_theta.nx * fr.v_theta.ny, 0.0);
    for (std::size_t j = 0; j < fr.v_theta.ny; ++j) {
      for (std::size_t i = 0; i < fr.v_theta.nx; ++i) {
        const int flat = grid.storage_index(0, static_cast<int>(i)) * grid.stride(0) +
                         grid.storage_index(1, static_cast<int>(j)) * grid.stride(1);
        double m = 0.0, mv = 0.0;
        for (int b : {grains_, fluid_}) {
          if (b < 0) continue;
          const auto& fld = solver_->field(b);
          m += fld.mass_kg[flat];
          mv += fld.mass_kg[flat] * fld.velocity[flat][2];
        }
        fr.v_theta.values[j * fr.v_theta.nx + i] = m > 0 ? mv / m : 0.0;
      }
    }
    if (grains_ >= 0 && granular_law_)  // the structure, for the structure front
      fr.f = nodal_average<G>(grid, {&solver_->body(grains_)},
                              [&](std::size_t, std::int64_t p) { return granular_law_->f[static_cast<std::size_t>(p)]; });
    shear_frames_.push_back(std::move(fr));
  }
}

template <class G>
nlohmann::json SceneRun<G>::parameters() const {
  const auto& s = cfg_.material.steady;
  const auto& g = cfg_.material.granular;
  nlohmann::json p;
  p["preset"] = cfg_.material.name;
  p["phi"] = cfg_.regions.front().phi;
  p["rho_s"] = g.rho_s;
  p["rho_f"] = cfg_.fluid.rho_f0_kg_m3;
  p["eta_0"] = cfg_.fluid.eta_0_Pa_s;
  p["kappa"] = cfg_.fluid.kappa_Pa;
  p["d"] = g.d;
  p["G"] = g.G;
  p["K"] = g.K;
  p["K_0"] = g.K_0;
  p["K_3"] = g.K_3;
  p["K_4"] = g.K_4;
  p["mu_1"] = s.mu_c;
  p["mu_2"] = g.mu_2 < 0 ? s.mu_c : g.mu_2;
  p["b"] = g.b;
  p["phi_c"] = s.phi_c;
  p["phi_j"] = s.phi_j;
  p["a_0"] = s.a_0;
  p["a_inf"] = s.a_inf;
  p["tau_star"] = s.tau_star;
  p["Delta"] = s.Delta;
  p["xi_dot_eps"] = s.xi_dot_eps;
  nlohmann::json terms = nlohmann::json::array();
  for (const auto& t : s.eta_B_terms) terms.push_back({{"phi_i", t.phi_i}, {"alpha", t.alpha}});
  p["eta_B"] = terms;
  p["gravity"] = std::vector<double>(cfg_.gravity_m_s2.begin(), cfg_.gravity_m_s2.begin() + D);
  p["porosity_min"] = cfg_.coupling.porosity_min;
  p["drag"] = cfg_.coupling.drag == scene::DragLaw::Beetstra ? "beetstra" : "carman_kozeny";
  p["cell_size"] = cfg_.grid.cell_size_m;
  p["cells"] = std::vector<int>(cfg_.grid.cells.begin(), cfg_.grid.cells.begin() + D);
  p["shape_function"] = scene::to_string(cfg_.grid.shape);
  p["transfer"] = cfg_.transfer.scheme == scene::TransferScheme::Apic ? "apic" : "flip";
  if (cfg_.transfer.scheme == scene::TransferScheme::Flip) p["flip_fraction"] = cfg_.transfer.flip_fraction;
  if (cfg_.grid.geometry == scene::Geometry::Axisymmetric) {
    p["r_inner"] = cfg_.grid.origin_m[0];
    p["r_outer"] = cfg_.grid.origin_m[0] + cfg_.grid.size_m[0];
    p["height"] = cfg_.grid.size_m[1];
    if (cfg_.boundary[0].type == BoundaryType::Velocity) p["u_inner"] = cfg_.boundary[0].velocity_m_s[2];
  }
  return p;
}

template <class G>
nlohmann::json SceneRun<G>::analysis_result() const {
  nlohmann::json a = nlohmann::json::object();
  if (cfg_.analysis.kind == scene::AnalysisKind::Settling) {
    // Drag-buoyancy balance (derivation in docs/verification.md): with zero mixture volume flux
    // the fluid pressure gradient carries the mixture weight, so per mixture volume the drag
    // balances phi (1 - phi)(rho_s - rho_f) g: 18 phi (1-phi) eta_0/d^2 F(phi, Re) w = phi (1-phi) drho g,
    // w = v_s - v_f the slip velocity; the grain velocity in the zero-flux frame is (1 - phi) w.
    const double phi = cfg_.regions.front().phi;
    const double g = std::fabs(cfg_.gravity_m_s2[D - 1]);
    const double drho = cfg_.material.granular.rho_s - cfg_.fluid.rho_f0_kg_m3;
    material::DragParams dp = solver_->options().mixture.drag;
    double w = 0.0;
    for (int it = 0; it < 100; ++it) {
      const double Re = material::drag_reynolds(w, 1.0 - phi, cfg_.fluid.rho_f0_kg_m3, dp.d_m, dp.eta_0_Pa_s);
      const double w_new = drho * g * dp.d_m * dp.d_m / (18.0 * dp.eta_0_Pa_s * material::drag_F(dp, phi, Re));
      if (std::fabs(w_new - w) <= 1e-14 * std::fabs(w_new)) {
        w = w_new;
        break;
      }
      w = w_new;
    }
    a["settling_velocity"] = settle_samples_ > 0 ? settle_sum_ / static_cast<double>(settle_samples_) : NAN;
    a["settling_velocity_analytic"] = (1.0 - phi) * w;
    a["settling_samples"] = settle_samples_;
  }
  if (cfg_.analysis.kind == scene::AnalysisKind::Annular && shear_frames_.size() >= 2) {
    // S1 (scenes.md): surface v_theta/u_i at 0, 0.1, 0.2, 0.31 rad of bob rotation, distance from
    // the Newtonian A r + B/r profile, jammed-front radius vs time and its speed, flow stop.
    const auto geo = annular_geometry();
    std::vector<double> angles;
    const double max_angle = geo.bob_speed_m_per_s * shear_frames_.back().time_s / geo.bob_radius_m;
    // The paper's angles, then later ones in longer runs (what the band does next).
    for (double th : {0.0, 0.1, 0.2, 0.31, 0.45, 0.6, 0.8, 1.0}) {
      if (th <= max_angle) angles.push_back(th);
    }
    const auto profiles = analysis::surface_profiles(shear_frames_, geo, angles);
    a["profiles"] = analysis::to_json(profiles);
    nlohmann::json dist = nlohmann::json::array();
    for (const auto& pr : profiles) dist.push_back(analysis::newtonian_distance(pr, geo));
    a["newtonian_distance"] = dist;
    a["bob_angle_final_rad"] = max_angle;
    const auto fronts = analysis::jammed_front_series(shear_frames_, geo);
    // The front speed is fitted while the front advances: up to its farthest extent (after that
    // the co-rotation fades and the front criterion recedes, see docs/results.md).
    const auto radii = analysis::front_radius_series(fronts);
    a["front"] = analysis::to_json(radii);
    double t_farthest = INFINITY;
    if (radii.size() > 0) {
      const auto k = static_cast<std::size_t>(std::max_element(radii.value.begin(), radii.value.end()) -
                                              radii.value.begin());
      t_farthest = radii.time[k];
      a["front_farthest"] = radii.value[k];
      a["front_farthest_time"] = t_farthest;
    }
    try {
      analysis::FrontFitOptions fo;
      fo.wall_margin_m = cfg_.grid.cell_size_m;
      fo.t_end_s = t_farthest;
      const analysis::LinearFit fit = analysis::front_speed(fronts, geo, fo);
      a["front_speed"] = fit.slope;
      a["front_fit"] = analysis::to_json(fit);
    } catch (const InputError& e) {
      a["front_speed"] = nullptr;
      a["front_fit_note"] = e.what();
    }
    // The bob keeps turning, so flow stops when the jammed front reaches the outer wall (no velocity criterion).
    const auto stop = analysis::flow_stop_time(shear_frames_, geo, 0.0, cfg_.grid.cell_size_m);
    a["flow_stop"] = analysis::to_json(stop);
    a["flow_stop_time"] = stop.time_s ? nlohmann::json(*stop.time_s) : nlohmann::json(nullptr);
    // The outer half's rotation relative to the bob and its arrest (below 10% of its peak).
    const auto outer = analysis::outer_rotation_series(shear_frames_, geo);
    a["outer_rotation"] = analysis::to_json(outer);
    a["outer_arrest"] = analysis::to_json(analysis::outer_arrest(outer, 0.1));
    // Whether the bob's speed admits a steady flow of the bed at its uniform phi (docs/analysis.md
    // "Annular shear"): the fastest steady shear of the flow curve, the simple bound it gives and
    // the exact 1D Couette limit (torque balance over the flow curve).
    {
      nlohmann::json sf;
      const double phi = cfg_.regions.front().phi;
      sf["phi"] = phi;
      sf["bob_speed"] = geo.bob_speed_m_per_s;
      try {
        const auto& sp = cfg_.material.steady;
        const auto lim = rheology::fastest_steady_shear(sp, phi);
        const auto dst = rheology::shear_rate_dst(sp, phi);
        sf["shear_rate_dst"] = dst ? nlohmann::json(*dst) : nlohmann::json(nullptr);
        if (lim) {
          sf["max_shear_rate"] = lim->shear_rate;
          sf["max_shear_rate_stress"] = lim->attained ? nlohmann::json(lim->shear_stress) : nlohmann::json(nullptr);
          sf["max_shear_rate_is_dst_asymptote"] = !lim->attained;
          sf["bob_speed_bound"] = analysis::steady_bob_speed_limit(lim->shear_rate, geo);
          std::vector<double> tau, rate;
          for (const auto& pt : rheology::flow_curve(sp, phi, 4000)) {
            tau.push_back(pt.shear_stress);
            rate.push_back(pt.shear_rate);
          }
          const auto c = analysis::steady_couette_limit(tau, rate, geo);
          double limit = c.bob_speed_m_per_s;
          // tau_0 -> infinity on a DST asymptote: omega_bob -> gamma_dot_DST ln(r_o/r_0).
          if (dst) limit = std::max(limit, analysis::steady_bob_speed_limit(*dst, geo));
          sf["bob_speed_limit"] = limit;
          sf["bob_speed_limit_stress"] = limit > c.bob_speed_m_per_s ? nlohmann::json(nullptr) : nlohmann::json(c.bob_stress_Pa);
          sf["steady_flow_possible"] = std::fabs(geo.bob_speed_m_per_s) <= limit;
        } else {  // unbounded flow curve (CST): every bob speed has a steady state
          sf["max_shear_rate"] = nullptr;
          sf["bob_speed_bound"] = nullptr;
          sf["bob_speed_limit"] = nullptr;
          sf["steady_flow_possible"] = true;
        }
      } catch (const std::exception& e) {  // phi >= phi_j (jammed, no steady flow), or a failed solve
        sf["note"] = e.what();
        sf["steady_flow_possible"] = nullptr;
      }
      a["steady_flow"] = sf;
    }
    // How far the jammed structure has spread: f >= half its E9 limit f_m(phi) of the bed.
    if (!shear_frames_.front().f.values.empty()) {
      const double f_thr = 0.5 * rheology::f_m(cfg_.material.steady, cfg_.regions.front().phi);
      const auto sfronts = analysis::structure_front_series(shear_frames_, geo, f_thr);
      a["structure_front"] = analysis::to_json(analysis::front_radius_series(sfronts));
      a["structure_front_threshold"] = f_thr;
      const auto t_wall = analysis::front_at_wall_time(sfronts, geo, cfg_.grid.cell_size_m);
      a["structure_front_wall_time"] = t_wall ? nlohmann::json(*t_wall) : nlohmann::json(nullptr);
    }
  }
  if (cfg_.analysis.kind == scene::AnalysisKind::Couette && fluid_ >= 0 && NC == 3) {
    // Torque on a coaxial cylinder of radius r: M(r) = 2 pi r^2 H tau_r_theta (whole cylinder).
    // At steady state r^2 tau_r_theta is uniform in the gap (torque balance); a least-squares line
    // of r^2 tau_r_theta against r over all fluid points, evaluated at each wall, gives the wall
    // torques (their difference measures the discretization error). Analytic: M = 4 pi eta B H.
    const auto& body = solver_->body(fluid_);
    const double ri = cfg_.grid.origin_m[0], ro = ri + cfg_.grid.size_m[0];
    const double H = cfg_.grid.size_m[1];
    double sr = 0, sm = 0, srr = 0, srm = 0;
    const auto np = static_cast<double>(body.size());
    for (std::int64_t p = 0; p < body.size(); ++p) {
      const double r = body.x_m[p][0];
      const double m = r * r * body.stress_Pa[p](0, 2);
      sr += r;
      sm += m;
      srr += r * r;
      srm += r * m;
    }
    const double slope = (np * srm - sr * sm) / (np * srr - sr * sr);
    const double icpt = (sm - slope * sr) / np;
    a["torque_inner"] = std::fabs(2.0 * M_PI * H * (icpt + slope * ri));
    a["torque_outer"] = std::fabs(2.0 * M_PI * H * (icpt + slope * ro));
    const double eta = cfg_.fluid.eta_0_Pa_s;
    const double U = cfg_.boundary[0].velocity_m_s[2];
    const double B = U * ri * ro * ro / (ro * ro - ri * ri);
    a["torque_analytic"] = std::fabs(4.0 * M_PI * eta * B * H);
    // Velocity profile error against A r + B/r at the points (L2 relative to U).
    const double A = -U * ri / (ro * ro - ri * ri);
    double e2 = 0.0;
    for (std::int64_t p = 0; p < body.size(); ++p) {
      const double r = body.x_m[p][0];
      const double d = body.v_m_s[p][2] - (A * r + B / r);
      e2 += d * d;
    }
    a["velocity_profile_rms_error"] = std::sqrt(e2 / static_cast<double>(body.size())) / std::fabs(U);
  }
  return a;
}

template <class G>
nlohmann::json SceneRun<G>::body_analysis() const {
  nlohmann::json out;
  // Every body: its motion, whole mass (axisymmetric: 2 pi x per radian; plane strain: per metre
  // of depth), final centre, velocity and contact force.
  nlohmann::json bodies = nlohmann::json::object();
  const double whole = std::is_same_v<G, mpm::Axisymmetric> ? 2.0 * M_PI : 1.0;
  for (const auto& tb : third_) {
    const auto& body = solver_->body(tb.body);
    const Vd c = centre_of_mass(body, solver_->grid());
    const Vn v = body.total_momentum() / body.total_mass();
    const Vn F = solver_->contact(tb.pair).force_N;
    bodies[tb.cfg->name] = {{"motion", scene::to_string(tb.cfg->motion)},
                            {"points", body.size()},
                            {"mass", whole * body.total_mass()},
                            {"centre", std::vector<double>(c.data(), c.data() + D)},
                            {"velocity", std::vector<double>(v.data(), v.data() + NC)},
                            {"contact_force_last_step", std::vector<double>(F.data(), F.data() + NC)}};
    if (tb.cfg->motion == scene::BodyMotionKind::Prescribed) bodies[tb.cfg->name]["ramp_time"] = tb.cfg->ramp_time_s;
  }
  out["bodies"] = bodies;
  if (analysed_ < 0 || track_.size() < 2) return out;
  const ThirdBody& tb = third_[static_cast<std::size_t>(analysed_)];
  const double h = cfg_.grid.cell_size_m;
  const double sample_dt = track_[1].t - track_[0].t;

  if (cfg_.analysis.kind == scene::AnalysisKind::Intrusion && !uz_frames_.empty()) {
    // S3 (scenes.md): fronts of u_z = fraction v_0 and of f = f_threshold below (longitudinal)
    // and beside (transverse) the intruder; speeds from straight-line fits before a front comes
    // within two cells of a wall; k_l = v_fl/v_0 - 1, k_t = v_ft/v_0.
    const double v0 = tb.cfg->velocity_m_s[1];
    analysis::FrontGeometry geo;
    geo.direction = v0 < 0 ? -1.0 : 1.0;
    geo.intruder_radius_m = tb.cfg->max_m[0];
    geo.axis_r_m = cfg_.grid.origin_m[0];
    std::size_t window = 1;
    if (cfg_.analysis.filter_window_s > 0) {
      window = static_cast<std::size_t>(std::llround(cfg_.analysis.filter_window_s / sample_dt));
      if (window % 2 == 0) ++window;
    }
    analysis::FrontFitOptions fo;
    fo.wall_margin_m = 2.0 * h;
    // The bed bottom is the longitudinal wall. k_l, k_t are defined at constant v_0: an intruder
    // that ramps up to speed is fitted from the first sample whose (centred) time window lies
    // after its ramp.
    fo.t_begin_s = tb.cfg->ramp_time_s > 0 ? tb.cfg->ramp_time_s + 0.5 * static_cast<double>(window - 1) * sample_dt : 0.0;
    auto fronts = [&](const std::vector<analysis::IntrusionFrame>& frames, const analysis::FrontCriterion& crit) {
      nlohmann::json j;
      const auto series = analysis::measure_front_series(frames, crit, geo, window);
      j["series"] = analysis::to_json(series);
      try {
        const auto sp = analysis::front_speeds(series, std::fabs(v0), fo);
        j["speeds"] = analysis::to_json(sp);
      } catch (const InputError& e) {
        j["speeds"] = nullptr;
        j["fit_note"] = e.what();
      }
      return j;
    };
    nlohmann::json vel = fronts(uz_frames_, analysis::velocity_front(v0, cfg_.analysis.front_fraction));
    out["velocity_front"] = vel;
    if (!f_frames_.empty()) out["f_front"] = fronts(f_frames_, analysis::scalar_front(cfg_.analysis.f_threshold));
    const nlohmann::json& sp = vel["speeds"];
    for (const char* k : {"v_fl", "v_ft", "k_l", "k_t", "k_l_over_k_t"})
      out[k] = sp.is_null() ? nlohmann::json(nullptr) : sp[k];
    out["v0"] = std::fabs(v0);
    out["ramp_time"] = tb.cfg->ramp_time_s;
    out["filter_window_frames"] = window;
    out["sample_interval"] = sample_dt;
  }

  if (cfg_.analysis.kind == scene::AnalysisKind::Rod) {
    // S2 (scenes.md): rod position, velocity, acceleration (from position by finite differences
    // over the stencil filter_window, and from the contact force), peak deceleration, impact time,
    // |dz| vs depth below the rod at the snapshot time.
    const double g = std::fabs(cfg_.gravity_m_s2[D - 1]);
    const double M = solver_->rigid_motion(tb.body).mass_kg;  // per radian, like the force
    analysis::TimeSeries zc, zb, Fz, vz;
    for (const auto& t : track_) {
      zc.time.push_back(t.t);
      zc.value.push_back(t.centre[D - 1]);
      zb.time.push_back(t.t);
      zb.value.push_back(t.bottom - 0.5 * h / tb.cfg->points_per_cell);
      vz.time.push_back(t.t);
      vz.value.push_back(t.velocity[D - 1]);
    }
    for (std::size_t k = 1; k < track_.size(); ++k) {  // force k: mean over (t_{k-1}, t_k]
      Fz.time.push_back(track_[k].t);
      Fz.value.push_back(track_[k].force[D - 1]);
    }
    std::size_t stencil = 1;
    if (cfg_.analysis.filter_window_s > 0)
      stencil = std::max<std::size_t>(1, static_cast<std::size_t>(std::llround(cfg_.analysis.filter_window_s / sample_dt)));
    out["rod_position"] = analysis::to_json(zb);
    out["rod_centre"] = analysis::to_json(zc);
    out["rod_velocity"] = analysis::to_json(vz);
    out["contact_force"] = analysis::to_json(Fz);
    out["rod_mass"] = (std::is_same_v<G, mpm::Axisymmetric> ? 2.0 * M_PI : 1.0) * M;
    const auto a_force = analysis::acceleration_from_force(Fz, M, g);
    out["rod_acceleration_from_force"] = analysis::to_json(a_force);
    out["peak_deceleration_from_force"] = analysis::to_json(analysis::peak_deceleration(a_force, -1.0));
    if (zb.size() >= 2 * stencil + 1) {
      const auto kin = analysis::rod_kinematics(zb, stencil, analysis::DifferenceTime::midpoint);
      out["rod_velocity_from_position"] = analysis::to_json(kin.velocity);
      out["rod_acceleration"] = analysis::to_json(kin.acceleration);
      out["peak_deceleration"] = analysis::to_json(analysis::peak_deceleration(kin.acceleration, -1.0));
    }
    out["difference_stencil_samples"] = stencil;
    const double surface = bed_surface();
    out["bed_surface"] = surface;
    if (auto ti = analysis::impact_time_from_position(zb, surface, -1.0)) out["impact_time"] = *ti;
    else out["impact_time"] = nullptr;
    out["final_depth"] = surface - zb.value.back();
    if (!rod_profile_.is_null()) out["displacement_below_rod"] = rod_profile_;
    out["final_velocity"] = vz.value.back();
  }

  if (cfg_.analysis.kind == scene::AnalysisKind::Wheel) {
    // S4 (scenes.md): hub (centre of mass) height and distance travelled vs time.
    analysis::HubTrack hub;
    for (const auto& t : track_) {
      hub.time_s.push_back(t.t);
      hub.x_m.push_back(t.centre[0]);
      hub.y_m.push_back(t.centre[1]);
    }
    analysis::WheelCriteria wc;
    wc.track_length_m = cfg_.grid.size_m[0];
    wc.wheel_radius_m = wheel_radius(tb);
    wc.bed_surface_m = bed_surface();
    double omega = tb.cfg->motor_omega_rad_s.value_or(0.0);
    wc.forward = omega > 0 ? -1.0 : 1.0;  // counter-clockwise rotation rolls towards -x
    const auto sum = analysis::summarize_wheel(hub, wc);
    out.update(analysis::to_json(sum, wc));
    analysis::TimeSeries height, dist, om;
    for (std::size_t k = 0; k < track_.size(); ++k) {
      height.time.push_back(track_[k].t);
      height.value.push_back(track_[k].centre[1]);
      dist.time.push_back(track_[k].t);
      dist.value.push_back(wc.forward * (sum.x_unwrapped_m[k] - sum.x_unwrapped_m[0]));
      om.time.push_back(track_[k].t);
      om.value.push_back(track_[k].omega);
    }
    out["hub_height"] = analysis::to_json(height);
    out["distance_travelled"] = analysis::to_json(dist);
    out["omega_measured"] = analysis::to_json(om);
    out["omega"] = omega;
    // SI figure: the pressure scatter at every frame, and pooled over the frames after t = 0.
    auto scatter_json = [](const analysis::PressureScatter& r) {
      return nlohmann::json{{"relative", r.relative}, {"rms_deviation", r.rms_deviation_Pa}, {"rms", r.rms_Pa},
                            {"points", r.points}, {"cells", r.cells}};
    };
    nlohmann::json series = nlohmann::json::array();
    std::vector<analysis::PressureScatter> later;
    for (const auto& r : pressure_scatter_) {
      auto j = scatter_json(r.s);
      j["time"] = r.t;
      series.push_back(j);
      if (r.t > 0.0) later.push_back(r.s);
    }
    out["pressure_scatter"] = {{"series", series}, {"pooled", scatter_json(analysis::pool(later))}};
  }
  return out;
}

template <class G>
nlohmann::json SceneRun<G>::run() {
  {
    std::error_code ec;
    fs::create_directories(opt_.out_dir, ec);
    if (ec || !fs::is_directory(opt_.out_dir))
      throw InputError(fmt::format("--out {}: cannot create the run folder: {}", opt_.out_dir,
                                   ec ? ec.message() : "a file of that name is in the way"));
  }
  const long every_frame = steps_between(cfg_.output.frame_interval_s, std::numeric_limits<long>::max());
  const long every_series = steps_between(cfg_.output.series_interval_s, 100);
  const long every_cp = opt_.checkpoint_every >= 0 ? opt_.checkpoint_every : cfg_.output.checkpoint_every;
  const bool annular = cfg_.analysis.kind == scene::AnalysisKind::Annular;
  const long every_sample = steps_between(
      cfg_.analysis.sample_interval_s > 0 ? cfg_.analysis.sample_interval_s : cfg_.time.duration_s / 200.0, 1);

  std::optional<io::FrameWriter> frames;
  std::optional<io::SeriesWriter> series;
  if (opt_.restart) {
    const io::Checkpoint cp = io::read_checkpoint(checkpoint_path(opt_.out_dir));
    restore(cp);
    frames.emplace(io::FrameWriter::resume(opt_.out_dir, cp.step()));
    series.emplace(io::SeriesWriter::resume(opt_.out_dir + "/series.csv", series_columns(), cp.time()));
  } else {
    io::write_file_atomically(stored_scene_path(opt_.out_dir), cfg_.resolved_toml, "scene copy");
    frames.emplace(opt_.out_dir);
    series.emplace(opt_.out_dir + "/series.csv", series_columns());
    write_frame(*frames);
    series->row(series_row());
  }
  if (annular && !opt_.restart) sample_shear_frame();  // a restart has its samples from the checkpoint
  const bool tracked = analysed_ >= 0;
  if (tracked && !opt_.restart) {
    sample_track();
    sample_intrusion_fields();
  }
  if (!opt_.restart) write_due_snapshots(false);

  std::int64_t points = 0;
  nlohmann::json per_body;
  for (int b = 0; b < solver_->body_count(); ++b) {
    points += solver_->body(b).size();
    per_body[solver_->body(b).name] = solver_->body(b).size();
  }
  io::ProgressOptions po;
  po.quiet = opt_.quiet;
  po.points_per_step = static_cast<double>(points);
  po.label = cfg_.name;
  io::Progress progress(static_cast<std::uint64_t>(total_steps_), po);

  const long first = static_cast<long>(solver_->steps());
  const long last = opt_.stop_after_steps >= 0 ? std::min<long>(opt_.stop_after_steps, total_steps_) : total_steps_;
  solver_->reset_timings();
  const auto t0 = std::chrono::steady_clock::now();
  for (long s = first + 1; s <= last; ++s) {
    for (const auto& tb : third_)  // prescribed bodies ramping up to speed
      if (tb.cfg->ramp_time_s > 0.0)
        solver_->set_prescribed_velocity(tb.body, prescribed_velocity<NC>(*tb.cfg, solver_->time_s(), dt_));
    solver_->step();
    check_finite();
    sample_analysis();
    if (annular && (s % every_sample == 0 || s == total_steps_)) sample_shear_frame();
    if (tracked && (s % every_sample == 0 || s == total_steps_)) {
      sample_track();
      sample_intrusion_fields();
    }
    write_due_snapshots(s == total_steps_);
    if (s % every_frame == 0 || s == total_steps_) write_frame(*frames);
    if (s % every_series == 0 || s == total_steps_) series->row(series_row());
    if (every_cp > 0 && s % every_cp == 0) write_checkpoint();
    progress.update(static_cast<std::uint64_t>(s), solver_->time_s());
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (last < total_steps_) write_checkpoint();  // stopped early: leave a checkpoint to continue from
  progress.finish();
  frames->flush();

  const long steps_run = last - first;
  const auto& tm = solver_->timings();
  nlohmann::json j;
  j["scene"] = cfg_.name;
  j["scene_file"] = cfg_.file;
  j["geometry"] = scene::to_string(cfg_.grid.geometry);
  j["points"] = points;
  j["points_per_body"] = per_body;
  j["steps"] = solver_->steps();
  j["steps_this_run"] = steps_run;
  j["complete"] = last == total_steps_;
  j["dt"] = dt_;
  j["time"] = solver_->time_s();
  j["wall_seconds"] = wall;
  j["point_updates_per_second"] = wall > 0 ? static_cast<double>(points) * static_cast<double>(steps_run) / wall : 0.0;
  j["threads"] = solver_->threads();
  j["library_instruction_set"] = library_instruction_set();  // which CPU variant ran
  j["timings_seconds"] = {{"p2g", tm.p2g}, {"grid", tm.grid}, {"g2p", tm.g2p},
                          {"stress", tm.stress}, {"output_and_checks", wall - tm.total()}};
  j["parameters"] = parameters();
  const nlohmann::json analysis = analysis_result();
  j.update(analysis);
  if (!third_.empty()) j.update(body_analysis());
  if (!snapshot_files_.empty()) j["snapshots"] = snapshot_files_;
  io::write_summary(opt_.out_dir, j);
  return j;
}

}  // namespace

nlohmann::json run_scene(const SceneConfig& config, const RunOptions& options) {
  if (options.out_dir.empty()) throw InputError("run: empty output folder");
  switch (config.grid.geometry) {
    case scene::Geometry::PlaneStrain: return SceneRun<mpm::PlaneStrain>(config, options).run();
    case scene::Geometry::Axisymmetric: return SceneRun<mpm::Axisymmetric>(config, options).run();
    case scene::Geometry::ThreeD: return SceneRun<mpm::ThreeD>(config, options).run();
  }
  return {};
}

}  // namespace oobleck::run
