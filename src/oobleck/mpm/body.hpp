#pragma once
// A body of material points in structure-of-arrays form, and the interface through which a
// constitutive law plugs in.
//
// Each field is one contiguous array over the points. Per-law state (e.g. f and φ of the granular
// phase, J of the fluid) lives in the law object attached to the body, again one array per
// variable; the law updates the body's stress from the body's velocity gradient once per step.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "oobleck/mpm/fields.hpp"
#include "oobleck/mpm/geometry.hpp"

namespace oobleck::mpm {

template <class G>
struct Body;

/// Answers of the NaN guards fused into the step's passes (G2P, the laws): every point finite, or
/// the pass does not check (otherwise they give the lowest index of a non-finite point).
inline constexpr std::int64_t kAllFinite = std::numeric_limits<std::int64_t>::max();
inline constexpr std::int64_t kNotChecked = -1;

/// What a law tells the solver's scheduler about its chunks (parallel.hpp).
struct ScheduleHint {
  /// Cost of one point's update relative to a simple law's: the costliest bodies' chunks run first.
  double relative_cost_per_point = 1.0;
  /// The chunks' costs vary: the threads steal each other's remaining chunks at the end of their
  /// static shares. Otherwise each thread runs only its static share, which holds the points it
  /// maps in G2P and scatters in P2G (their data stay in its core's caches).
  bool uneven_chunks = false;
};

/// A stress law for a whole body (one virtual call per body per step; the loop over points and the
/// per-point pure function are inside). Implementations own their per-point state arrays.
template <class G>
class StressLaw {
 public:
  virtual ~StressLaw() = default;
  /// Called whenever points are added, so the law can size its state (new points get defaults).
  virtual void resize(std::int64_t n_points) = 0;
  /// The update of body.stress from body.L (and the law's state) over one step of length dt [s],
  /// in independent chunks of points: the solver runs every chunk (in parallel, any order; see
  /// Solver::update_points), then end_update once. The number of chunks of the step:
  virtual std::int64_t chunk_count(const Body<G>& body) const = 0;
  /// chunk c's update; returns the lowest index of a point of the chunk whose new stress is not
  /// finite, or kAllFinite. Chunks touch only their own points' state.
  virtual std::int64_t update_chunk(Body<G>& body, double dt_s, std::int64_t c) = 0;
  /// Once after all chunks, with the lowest such index over the body (a law that stops the run
  /// on it throws here).
  virtual void end_update(Body<G>& body, double dt_s, std::int64_t first_bad) = 0;
  /// How the solver should schedule the chunks (see ScheduleHint).
  virtual ScheduleHint schedule_hint() const { return {}; }
  /// Fastest wave speed [m/s] at the current state (for the stable time step, docs/mpm.md "The step").
  virtual double max_wave_speed(const Body<G>& body) const = 0;
  /// Largest stable Δt [s] of the law's own diffusion on a grid of cell size h (viscous limit
  /// ρ h²/(2η), docs/mpm.md "The step"); +∞ for laws without one.
  virtual double viscous_dt_limit(const Body<G>& /*body*/, double /*h_m*/) const { return INFINITY; }
  /// Short name for messages.
  virtual const char* name() const = 0;
  /// The NaN guard fused into the chunks' update: the lowest index of a point whose new stress is not
  /// finite, kAllFinite, or kNotChecked (the default: the runner then scans the stresses itself).
  virtual std::int64_t first_non_finite_stress() const { return kNotChecked; }
  /// Declare the law's persistent per-point arrays (checkpoints) and what it adds to its body's
  /// frames (mpm/fields.hpp); called after the body declared its own. Default: none.
  virtual void declare_fields(Body<G>& /*body*/, FieldList& /*list*/) {}
};

template <class G>
struct Body {
  static constexpr int D = G::dim;
  static constexpr int NC = G::ncomp;

  std::string name;
  std::vector<double> mass_kg;     ///< point mass (per radian in axisymmetric mode)
  std::vector<double> volume_m3;   ///< current point volume V_p
  std::vector<double> volume0_m3;  ///< initial point volume
  std::vector<Vec<D>> x_m;         ///< position
  std::vector<Vec<NC>> v_m_s;      ///< velocity
  std::vector<Mat<NC, D>> C_1_s;   ///< APIC affine velocity matrix (ncomp × dim)
  std::vector<Mat3> L_1_s;  ///< 3×3 velocity gradient of the last step, geometry terms incl. (axisymmetric: relative to
                            ///< the turning local basis, geometry.hpp)
  std::vector<Mat3> stress_Pa;   ///< Cauchy stress, positive in tension
  std::vector<Vec<NC>> f_ext_N;  ///< external force on the point (surface loads), spread by N_ip
  // Mixture fields interpolated from the nodes in G2P (fluid phase of a mixture only):
  std::vector<double> phi;        ///< granular volume fraction 1 − n at the point
  std::vector<double> div_q_1_s;  ///< div of the mixture volume flux q (E27)
  /// Reference positions (the snapshots' grain displacements since t = 0, run/snapshots.cpp):
  /// kept only while `keeps_x0` (set on every rank alike), empty otherwise. A per-point array
  /// like the others: it is checkpointed and travels with its point between ranks.
  bool keeps_x0 = false;
  std::vector<Vec<D>> x0_m;
  std::unique_ptr<StressLaw<G>> law;

  std::int64_t size() const { return static_cast<std::int64_t>(mass_kg.size()); }

  /// The persistent fields (mpm/fields.hpp): the arrays above, in the checkpoints' order (the
  /// law declares its own: StressLaw::declare_fields). Adding an array here puts it into
  /// checkpoints (and frames, with a FrameForm).
  void declare_fields(FieldList& list) {
    list.add("mass", mass_kg, "kg", FrameForm::scalar);
    list.add("volume", volume_m3, "m^3", FrameForm::scalar);
    list.add("volume0", volume0_m3, "m^3");
    list.add("x", x_m, "m", FrameForm::position, "position");
    list.add("v", v_m_s, "m/s", FrameForm::vector, "velocity");
    list.add("C", C_1_s, "1/s");
    list.add("L", L_1_s, "1/s");
    list.add("stress", stress_Pa, "Pa", FrameForm::sym_tensor);
    list.derived("pressure", "Pa", [this](std::span<double> out) {
      for (std::size_t p = 0; p < out.size(); ++p) out[p] = -stress_Pa[p].trace() / 3.0;
    });
    list.add("f_ext", f_ext_N, "N");
    list.add("phi", phi, "1");
    list.add("div_q", div_q_1_s, "1/s");
    // (checkpoints before the reference positions lived in the body read them from the snapshots'
    // "analysis/x0_grains")
    if (keeps_x0) list.add("x0", x0_m, "m", FrameForm::none, {}, "/analysis/x0_grains", [](double x) { return x; });
    list.frame_order({"x", "v", "stress", "pressure", "mass", "volume"});
  }

  /// Append one point at rest-state stress zero.
  void add_point(const Vec<D>& x, double volume, double density_kg_m3, const Vec<NC>& v = Vec<NC>::Zero()) {
    mass_kg.push_back(volume * density_kg_m3);
    volume_m3.push_back(volume);
    volume0_m3.push_back(volume);
    x_m.push_back(x);
    v_m_s.push_back(v);
    C_1_s.push_back(Mat<NC, D>::Zero());
    L_1_s.push_back(Mat3::Zero());
    stress_Pa.push_back(Mat3::Zero());
    f_ext_N.push_back(Vec<NC>::Zero());
    phi.push_back(0.0);
    div_q_1_s.push_back(0.0);
    if (keeps_x0) x0_m.push_back(x);
    if (law) law->resize(size());
  }

  /// Resize every point array (and the law's state) to n points; new points are zero.
  void resize(std::int64_t n) {
    const auto s = static_cast<std::size_t>(n);
    mass_kg.resize(s, 0.0);
    volume_m3.resize(s, 0.0);
    volume0_m3.resize(s, 0.0);
    x_m.resize(s, Vec<D>::Zero());
    v_m_s.resize(s, Vec<NC>::Zero());
    C_1_s.resize(s, Mat<NC, D>::Zero());
    L_1_s.resize(s, Mat3::Zero());
    stress_Pa.resize(s, Mat3::Zero());
    f_ext_N.resize(s, Vec<NC>::Zero());
    phi.resize(s, 0.0);
    div_q_1_s.resize(s, 0.0);
    if (keeps_x0) x0_m.resize(s, Vec<D>::Zero());
    if (law) law->resize(n);
  }

  void set_law(std::unique_ptr<StressLaw<G>> l) {
    law = std::move(l);
    if (law) law->resize(size());
  }

  /// Total mass [kg].
  double total_mass() const {
    double m = 0.0;
    for (double mp : mass_kg) m += mp;
    return m;
  }
  /// Total linear momentum [kg m/s] (point velocities).
  Vec<NC> total_momentum() const {
    Vec<NC> P = Vec<NC>::Zero();
    for (std::int64_t p = 0; p < size(); ++p) P += mass_kg[p] * v_m_s[p];
    return P;
  }
  /// Kinetic energy [J] of the point velocities.
  double kinetic_energy() const {
    double e = 0.0;
    for (std::int64_t p = 0; p < size(); ++p) e += 0.5 * mass_kg[p] * v_m_s[p].squaredNorm();
    return e;
  }
};

/// Fill a box [lo, hi] with points on a regular lattice of `ppc` points per cell per axis
/// (cell size h), all of density ρ, velocity from v(x). Point volume from the geometry's measure
/// (per radian, A r, in axisymmetric mode).
template <class G, class VFun>
void fill_box(Body<G>& body, const Vec<G::dim>& lo, const Vec<G::dim>& hi, double h_m, int ppc, double density_kg_m3,
              VFun&& velocity) {
  constexpr int D = G::dim;
  const double dx = h_m / ppc;
  int n[D];
  std::int64_t total = 1;
  for (int a = 0; a < D; ++a) {
    n[a] = static_cast<int>(std::lround((hi[a] - lo[a]) / dx));
    total *= n[a];
  }
  double vol = 1.0;
  for (int a = 0; a < D; ++a) vol *= dx;
  for (std::int64_t q = 0; q < total; ++q) {
    std::int64_t rem = q;
    Vec<D> x;
    for (int a = D - 1; a >= 0; --a) {
      const auto i = rem % n[a];
      rem /= n[a];
      x[a] = lo[a] + (static_cast<double>(i) + 0.5) * dx;
    }
    body.add_point(x, G::measure(x, vol), density_kg_m3, velocity(x));
  }
}

}  // namespace oobleck::mpm
