#pragma once
// Third bodies and their contact with the mixture (docs/contact.md).
//
// * Rigid bodies are ordinary material-point bodies (so they scatter a nodal mass field and a mass
//   gradient for the contact normal) whose points move rigidly instead of following the grid:
//     - Prescribed: every point moves at the body's velocity, every step, exactly (intruder; the
//                   caller may change it between steps: a ramp up to speed);
//     - FreeRigid:  translation only, V_{n+1} = V_n + Δt g + (Σ_i J_i)/M with J_i the contact
//                   impulses the body received at its nodes (launched rod), the impulses solved
//                   for the body as a whole (resolve_rigid_contact). Components whose
//                   `free_mask` entry is 0 are held (axisymmetric: only v_z is free).
// * Elastic bodies are Solid bodies with any law (LinearElasticLaw): the contact impulses change
//   their nodal velocities like any other force; a `Motor` holds their mean angular velocity.
// * Contact (docs/contact.md) at every node where the solid and the mixture (grains and/or fluid) both
//   have mass *and their nodal volumes overlap*: Σ_p N_ip V_p summed over the solid's and the
//   mixture's points is ≥ θ V_node (θ = `overlap_threshold`, 0.98; V_node = h^D, per radian h² r).
//   By the partition of unity two bodies that exactly touch fill every node's volume (sum = 1),
//   a gap leaves it below 1, and at a corner next to empty space it is well below 1. The pure
//   "both have mass" rule of the model (θ = 0) acts up to a cell early at every edge (see
//   docs/contact.md for what it does to a sliding block). The outward normal of the solid is
//   n = ∇m_b/|∇m_b| with ∇m_b,i = Σ_p m'_p ∇N_i(x_p), m'_p the point's mass in the grid's plane
//   (normal_weight: m_p/r_p in axisymmetric mode). At a node outside the body every ∇N_i(x_p)
//   points from the body's points towards the node: outward. The gradients are folded at walls
//   like the masses (fold_wall_gradient: walls and the axis are mirror planes), so a face
//   perpendicular to a wall has its normal along the wall up to the wall node. Only phases that approach the solid,
//   (v_k − v_b)·n < 0, are touched:
//     both grains and fluid approach: the three share the mass-weighted normal velocity
//       v_n* = (m_b v_b·n + m_s v_s·n + m_f v_f·n)/(m_b + m_s + m_f)        (three-body)
//     one phase k approaches:  v_n* = (m_b v_b·n + m_k v_k·n)/(m_b + m_k)   (two-body)
//   Both approach but one, k, is slower towards the solid than the three-body v_n* (v_k·n > v_n*;
//   e.g. a fast fluid pushes the solid away from slowly approaching grains): k is not in contact
//   after all, and the other phase's two-body rule applies (its v_n* is lower still, so k stays
//   out). A phase that does not approach keeps v_k·n ≥ v_b·n ≥ v_n*: it never approaches after
//   the step. All normal impulses are ≥ 0 (no phase is pulled). Normal impulse on phase k: J_k = m_k (v_n* − v_k·n) n.
//   Coulomb friction acts between solid and grains only (the fluid slips): the tangential impulse
//   on the grains is min(μ |J_s|, m_red |w_t|) against the tangential relative velocity w_t after
//   the normal step, m_red = m_s m_b/(m_s + m_b) (m_s for a prescribed body: infinite mass).
//   Everything is an impulse [kg m/s] on the nodal momenta; a force is impulse/Δt. (The authors'
//   stick branch used the stick momentum as a force, a missing 1/Δt (docs/contact.md, "Units"). Here
//   stick and slip are both impulses, so they cannot disagree in units.)
//   The solid receives J_b = −(J_s + J_f) at each node: momentum is conserved exactly node by node.
// * A prescribed body has infinite mass in the contact: v_n* = v_b·n, and J_b is the reaction.
// * The contact force on the solid, F = Σ_i J_b,i / Δt [N], is an output of every contact pair
//   (per radian in axisymmetric mode, like the masses: rod acceleration = F_z / M, both per radian).
//
// Free functions over arrays; the Solver (solver.hpp) calls them in its grid pass. No allocation
// inside a step (the nodal mass-gradient buffer is sized once).
//
// Decomposed runs (docs/mpi.md): every rank holds each rigid body's motion and each pair's sums,
// and sees the points of its block only. The functions here talk to no other rank: each returns
// (or adds to) this rank's share of a whole-body sum — the motor's moments (BodyMoments), the
// rigid contact's normal system (RigidSystem), a pair's impulses (PairSums) — and the step
// (mpm/phases/contact.hpp) completes the shares over the ranks with comm::sum_ordered, which gives
// every rank the same bits, so the ranks advance the bodies identically. The node sums count owned
// nodes only (the node weights are 0 on the ghost nodes that another rank owns); the positions are
// compared on the global grid.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>
#include <Eigen/LU>

#include "oobleck/mpm/body.hpp"
#include "oobleck/mpm/boundary.hpp"
#include "oobleck/mpm/fields.hpp"
#include "oobleck/mpm/grid.hpp"
#include "oobleck/mpm/shape.hpp"
#include "oobleck/mpm/transfer.hpp"

namespace oobleck::mpm {

/// How a body's points move (docs/contact.md).
enum class BodyMotion {
  Deformable,  ///< ordinary MPM body (law, G2P)
  Prescribed,  ///< rigid, every point at `RigidMotion::velocity_m_s`, forever
  FreeRigid,   ///< rigid, translation only, velocity from gravity and the contact impulses
};

/// Rigid motion of one body.
template <class G>
struct RigidMotion {
  static constexpr int NC = G::ncomp;
  BodyMotion kind = BodyMotion::Deformable;
  Vec<NC> velocity_m_s = Vec<NC>::Zero();   ///< v_0 (Prescribed) or the current V (FreeRigid)
  Vec<NC> free_mask = Vec<NC>::Ones();      ///< FreeRigid: 1 = component free, 0 = held fixed
  double mass_kg = 0.0;                     ///< Σ m_p (per radian in axisymmetric mode)
  Vec<NC> predicted_m_s = Vec<NC>::Zero();  ///< V + Δt g of the current step (internal)
  bool rigid() const { return kind != BodyMotion::Deformable; }
  /// Persistent state (mpm/fields.hpp): the velocity (a FreeRigid body's is integrated).
  void declare_fields(FieldList& list) { list.add_values("rigid_velocity", {velocity_m_s.data(), NC}, "m/s"); }
};

/// The cells of a translating rigid body's point lattice in its own frame, relative to its first
/// point: cell c holds a point at x_0 + c dx (dx the lattice spacing, (V_p/measure(x_p, 1))^(1/D)
/// of its smallest point). A rigid body only translates, so its cells never change; they are
/// built from the points at the first use (after a restart, from the restored points; decomposed
/// runs: before the points are split over the ranks). The anchor x_0 moves with the body
/// (move_anchor), so a rank without points of the body still knows where it is.
template <int D>
struct RigidShape {
  bool built = false;
  Vec<D> anchor_m = Vec<D>::Zero();     ///< x_0, the first point's position (moved with the body)
  double dx_m = 0.0;                    ///< lattice spacing
  std::array<int, D> lo{}, n{};         ///< cell index range: lo .. lo + n − 1 per axis
  std::vector<unsigned char> occupied;  ///< 1 where a point of the body sits, row-major over n
  bool occupied_at(const std::array<int, D>& c) const {
    std::int64_t k = 0;
    for (int a = 0; a < D; ++a) {
      const int j = c[a] - lo[a];
      if (j < 0 || j >= n[a]) return false;
      k = k * n[a] + j;
    }
    return occupied[static_cast<std::size_t>(k)] != 0;
  }
};

/// Contact between one solid body and the mixture (grains and/or fluid), docs/contact.md.
template <class G>
struct ContactPair {
  static constexpr int NC = G::ncomp;
  int solid = -1;                               ///< body index of the solid
  double friction_coefficient = 0.0;            ///< Coulomb μ between solid and grains [-]
  Vec<NC> force_N = Vec<NC>::Zero();            ///< contact force on the solid, last step [N]
  Vec<NC> force_on_grains_N = Vec<NC>::Zero();  ///< part of −force_N acting on the grains [N]
  Vec<NC> impulse_sum_N_s = Vec<NC>::Zero();    ///< Σ over all steps of the impulse on the solid
  /// Contact detection (see header): a node is a contact candidate where both have mass and the
  /// nodal volumes overlap, (V_b,i + V_mix,i) ≥ overlap_threshold · V_node,i. 0 disables the
  /// volume test (contact wherever both have mass, the model literally).
  double overlap_threshold = 0.98;
  /// Normal from the solid's mass gradient alone (false), or the combined normal of the pair
  /// n = (∇m_b − ∇m_mix)/|∇m_b − ∇m_mix| (true, default; the mixture's mass gradient from its
  /// grains, or its fluid when there are no grains; costs one serial scatter over the mixture's
  /// points per step). Sliding block (docs/contact.md): horizontal/normal force 0.317 with the
  /// combined normal vs 0.337 with the solid's alone, for μ = 0.3 at 32 cells/m.
  bool combined_normal = true;
  int active_nodes = 0;  ///< nodes where an impulse acted, last step
  /// Free rigid body: mixture points put back outside it after the last step (keep_points_out).
  int points_kept_out = 0;
  RigidShape<G::dim> shape;                ///< free rigid body: its cells (built at the first step)
  std::vector<Vec<G::dim>> mass_gradient;  ///< nodal ∇m_b (sized once)
  std::vector<double> volume_m3;           ///< nodal volume Σ N_ip V_p of the solid (sized once)
  /// Persistent state (mpm/fields.hpp): the impulse sum (the other members are per step).
  void declare_fields(FieldList& list) { list.add_values("impulse_sum", {impulse_sum_N_s.data(), NC}, "N s"); }
  /// The nodal sums and their halo rule (fields.hpp): completed on their owners before the
  /// impulses.
  void declare_nodal_fields(NodalFieldList& list) {
    list.add("contact_mass_gradient", mass_gradient, HaloRule::sum_before_contact);
    list.add("contact_volume", volume_m3, HaloRule::sum_before_contact);
  }
};

/// Velocity-level motor (docs/contact.md, wheel): before each step, the mean angular velocity of the
/// body about its centre of mass in the plane of the first and the last axis (plane strain: x, y;
/// 3D: x, z, the rotation about the y axis, counter-clockwise from +x towards +z, as in plane
/// strain), ω̄ = Σ m (x − x_c) × (v − V_c) / Σ m |x − x_c|² with both vectors taken in that plane,
/// is moved to the target by a rigid rotation increment Δω = gain (ω* − ω̄) of every point's
/// velocity in the plane, v_p += Δω (−r_2, r_1) (r = x_p − x_c; the APIC matrix C_p gains the
/// gradient of that increment, Δω [[0, −1], [1, 0]] on the plane's components). Σ m (x − x_c) = 0,
/// so the linear momentum (translation) is untouched: the body is free to translate, fall, roll.
/// The motor torque is I Δω/Δt (plane strain: per unit depth). Plane strain and 3D.
template <class G>
struct Motor {
  int body = -1;
  double omega_rad_s = 0.0;                    ///< target mean angular velocity ω* (counter-clockwise positive)
  double gain = 1.0;                           ///< fraction of the error removed per step, (0, 1]
  double omega_measured_rad_s = 0.0;           ///< ω̄ before the last correction
  double torque_N_m = 0.0;                     ///< motor torque of the last step, I Δω/Δt
  double inertia_kg_m2 = 0.0;                  ///< I = Σ m |x − x_c|² at the last step
  Vec<G::dim> centre_m = Vec<G::dim>::Zero();  ///< centre of mass at the last step
};

/// Minimum-image difference x − x_ref on periodic axes (a body straddling a periodic seam).
template <int D>
Vec<D> periodic_difference(const Grid<D>& grid, const Vec<D>& x, const Vec<D>& x_ref) {
  Vec<D> d = x - x_ref;
  for (int a = 0; a < D; ++a) {
    if (!grid.periodic[a]) continue;
    const double L = grid.length(a);
    // Within 0.49 L, round(d/L) is ±0 and d − L round(d/L) = d + 0 (a −0 difference becomes +0):
    // no division and no libm call for the usual case (a per-point test of the contact scatters).
    if (std::fabs(d[a]) < 0.49 * L) {
      d[a] += 0.0;
      continue;
    }
    d[a] -= L * std::round(d[a] / L);
  }
  return d;
}

/// A position for the minimum-image differences of a body's points (periodic axes): its first
/// point on this rank; not finite when it has none here. (A decomposed run's reference is the
/// same on every rank: along each axis the least of the ranks' first points' coordinates, a
/// coordinate of one of the body's points. The step and the run's measures take that minimum.)
template <class G>
Vec<G::dim> body_reference(const Body<G>& body) {
  return body.size() > 0 ? body.x_m[0] : Vec<G::dim>::Constant(INFINITY);
}

/// The moments of a body's points for its angular state (see Motor) in the plane of the first and
/// last axes, positions unwrapped about the reference x0 on periodic axes, in two stages: the
/// second reads the first's centre and mean velocity. Each stage adds this rank's share of a sum
/// over the body's points; a decomposed run completes a stage over the ranks before the next one.
template <class G>
struct BodyMoments {
  static constexpr int D = G::dim, NC = G::ncomp;
  Vec<D> x0 = Vec<D>::Zero();              ///< the reference (the same on every rank)
  std::array<double, 1 + D + NC> first{};  ///< M, Σ m (x − x0), Σ m v
  std::array<double, 2> second{};          ///< Σ m r × u, Σ m |r|² in the plane (about the centre, mean velocity)
  /// The centre of mass less x0, from the first stage.
  Vec<D> centre_offset() const {
    Vec<D> dc;
    for (int k = 0; k < D; ++k) dc[k] = first[1 + k] / first[0];
    return dc;
  }
  /// The mean velocity, from the first stage.
  Vec<NC> mean_velocity() const {
    Vec<NC> v;
    for (int k = 0; k < NC; ++k) v[k] = first[1 + D + k] / first[0];
    return v;
  }
};

/// Stage 1 of BodyMoments: mass, first moment about x0 and momentum of this rank's points.
template <class G>
void add_first_moments(BodyMoments<G>& m, const Body<G>& body, const Grid<G::dim>& grid) {
  constexpr int D = G::dim, NC = G::ncomp;
  for (std::int64_t p = 0; p < body.size(); ++p) {
    const double mp = body.mass_kg[p];
    const Vec<D> d = mp * periodic_difference<D>(grid, body.x_m[p], m.x0);
    const Vec<NC> mv = mp * body.v_m_s[p];
    m.first[0] += mp;
    for (int k = 0; k < D; ++k) m.first[1 + k] += d[k];
    for (int k = 0; k < NC; ++k) m.first[1 + D + k] += mv[k];
  }
}

/// Stage 2 of BodyMoments (the first complete): this rank's points' angular momentum and inertia
/// in the plane about the centre of mass, relative to the mean velocity.
template <class G>
void add_second_moments(BodyMoments<G>& m, const Body<G>& body, const Grid<G::dim>& grid) {
  constexpr int D = G::dim, NC = G::ncomp, a = 0, b = D - 1;
  const Vec<D> dc = m.centre_offset();
  const Vec<NC> velocity = m.mean_velocity();
  for (std::int64_t p = 0; p < body.size(); ++p) {
    const double mp = body.mass_kg[p];
    const Vec<D> r = periodic_difference<D>(grid, body.x_m[p], m.x0) - dc;
    const Vec<NC> u = body.v_m_s[p] - velocity;
    m.second[0] += mp * (r[a] * u[b] - r[b] * u[a]);
    m.second[1] += mp * (r[a] * r[a] + r[b] * r[b]);
  }
}

/// Mean angular velocity, inertia, centre of mass and mean velocity (every component) of a body
/// in the plane of the first and last axes (see Motor); all zero for a body without points.
template <class G>
struct AngularState {
  double omega_rad_s = 0.0, inertia_kg_m2 = 0.0;
  Vec<G::dim> centre_m = Vec<G::dim>::Zero();
  Vec<G::ncomp> velocity_m_s = Vec<G::ncomp>::Zero();
};

/// The angular state from complete moments (`grid`: the global grid).
template <class G>
AngularState<G> angular_state(const BodyMoments<G>& m, const Grid<G::dim>& grid) {
  static_assert(G::dim == G::ncomp, "angular_state: plane strain and 3D (not axisymmetric)");
  AngularState<G> st;
  st.velocity_m_s = m.mean_velocity();
  st.inertia_kg_m2 = m.second[1];
  st.omega_rad_s = st.inertia_kg_m2 > 0.0 ? m.second[0] / st.inertia_kg_m2 : 0.0;
  st.centre_m = m.x0 + m.centre_offset();
  grid.wrap(st.centre_m);
  return st;
}

/// The angular state of a body from the points on this rank alone (a run on one rank).
template <class G>
AngularState<G> angular_state(const Body<G>& body, const Grid<G::dim>& grid) {
  BodyMoments<G> m;
  m.x0 = body_reference(body);
  if (!std::isfinite(m.x0[0])) return {};  // no points
  add_first_moments(m, body, grid);
  add_second_moments(m, body, grid);
  return angular_state(m, grid);
}

/// Apply one motor correction (see Motor) to its body before the step, from the body's angular
/// state over all its points (`grid`: the global grid).
template <class G>
void apply_motor(Motor<G>& motor, Body<G>& body, const Grid<G::dim>& grid, const AngularState<G>& state, double dt_s) {
  constexpr int D = G::dim, NC = G::ncomp, a = 0, b = D - 1;
  const double dw = motor.gain * (motor.omega_rad_s - state.omega_rad_s);
  const std::int64_t np = body.size();
  Mat<NC, NC> dC = Mat<NC, NC>::Zero();
  dC(a, b) = -dw;
  dC(b, a) = dw;
  for (std::int64_t p = 0; p < np; ++p) {
    const Vec<D> r = periodic_difference<D>(grid, body.x_m[p], state.centre_m);
    body.v_m_s[p][a] -= dw * r[b];
    body.v_m_s[p][b] += dw * r[a];
    body.C_1_s[p] += dC;
  }
  motor.omega_measured_rad_s = state.omega_rad_s;
  motor.inertia_kg_m2 = state.inertia_kg_m2;
  motor.centre_m = state.centre_m;
  motor.torque_N_m = state.inertia_kg_m2 * dw / dt_s;
}

/// Predicted velocity of a rigid body (its mass rm.mass_kg set by the caller, over every rank);
/// its nodal velocity (and v_old) set to the rigid velocity on every node with mass (docs/contact.md).
template <class G>
void predict_rigid(RigidMotion<G>& rm, GridField<G>& field, const Vec<G::ncomp>& gravity, double dt_s) {
  rm.predicted_m_s = rm.velocity_m_s;
  if (rm.kind == BodyMotion::FreeRigid) rm.predicted_m_s += dt_s * gravity.cwiseProduct(rm.free_mask);
  const int nn = field.nodes();
  for (int i = 0; i < nn; ++i) {
    if (field.mass_kg[i] > 0.0) {
      field.velocity_old[i] = rm.velocity_m_s;
      field.velocity[i] = rm.predicted_m_s;
    } else {
      field.velocity_old[i].setZero();
      field.velocity[i].setZero();
    }
  }
}

/// The weight of point p in a contact normal's mass gradient: the point's mass in the grid's
/// plane, m_p in plane strain (and 3D); in axisymmetric mode (masses per radian, m_p = ρ_p A_p r_p,
/// docs/mpm.md) m_p/r_p = ρ_p A_p, the mass of its cross-section in the (r, z) plane. Σ_p ρ_p A_p ∇N_ip
/// is the gradient of the smoothed density, zero inside a uniform body: the normal is a property
/// of the body's shape. The per-radian masses would add the gradient of the factor r,
/// Σ_p m_p ∇N_ip ≈ ρ ∫ r ∇N_i dA = −ρ ∫ N_i dA ê_r (−ρ h² ê_r per node) inside a uniform body;
/// against a surface's own gradient, ~ρ r_i h × (the node's uncovered share of its support), it
/// tilts the normal of a face perpendicular to the axis by ~h/r_i (measured: n_r = −0.37, −0.16,
/// −0.08 at r = h, 2h, 3h under a flat face with quadratic B-splines; test
/// Contact.NormalUnderAFlatFaceIsMinusEzAtEveryRadius). Every body, prescribed, free or deformable.
template <class G>
double normal_weight(const Body<G>& body, std::int64_t p) {
  if constexpr (G::has_hoop_terms)
    return body.mass_kg[p] / G::measure(body.x_m[p], 1.0);
  else
    return body.mass_kg[p];
}

/// Nodal mass gradient ∇m_b,i = Σ_p m'_p ∇N_ip (m'_p = normal_weight) and nodal volume
/// Σ_p N_ip V_p of a body (its shape cache of the step); `grad` may be null (volume only).
template <class G, int K>
void scatter_mass_gradient_and_volume(const Body<G>& body, const ShapeCache<G::dim>& cache,
                                      std::vector<Vec<G::dim>>* grad, std::vector<double>& volume) {
  if (grad)
    for (auto& g : *grad) g.setZero();
  std::fill(volume.begin(), volume.end(), 0.0);
  constexpr int D = G::dim, S = support_of<D>(K);
  const std::int64_t np = body.size();
  for (std::int64_t p = 0; p < np; ++p) {
    const double m = normal_weight(body, p), V = body.volume_m3[p];
    for_each_node<D, S>(cache.template stencil<S>(p), [&](int i, double w, const double* g, const double*) {
      if (grad) (*grad)[i] += m * Eigen::Map<const Vec<D>>(g);
      volume[i] += w * V;
    });
  }
}

/// Nodal mass gradient ∇m_i = Σ_p m'_p ∇N_ip (m'_p = normal_weight) of the points of `body` that
/// lie within `half` of `centre` along every axis (minimum image on periodic axes); the others are
/// skipped. Used for the mixture's gradient, which contact reads only at nodes where a solid has
/// mass: with the box around the solids' points grown by two kernel widths, every point that
/// reaches such a node is inside, in the same order, so those nodes get exactly the full
/// scatter's values.
template <class G, int K>
void scatter_mass_gradient_near(const Body<G>& body, const ShapeCache<G::dim>& cache, const Grid<G::dim>& grid,
                                const Vec<G::dim>& centre, const Vec<G::dim>& half, std::vector<Vec<G::dim>>& grad) {
  constexpr int D = G::dim, S = support_of<D>(K);
  for (auto& g : grad) g.setZero();
  const std::int64_t np = body.size();
  for (std::int64_t p = 0; p < np; ++p) {
    const Vec<D> d = periodic_difference<D>(grid, body.x_m[p], centre);
    if ((d.cwiseAbs().array() > half.array()).any()) continue;
    const double m = normal_weight(body, p);
    for_each_node<D, S>(cache.template stencil<S>(p), [&](int i, double, const double* g, const double*) {
      grad[i] += m * Eigen::Map<const Vec<D>>(g);
    });
  }
}

/// The contact normal at node i (see the header): the unit vector along ∇m_b,i (minus the
/// mixture's ∇m_i with the combined normal, `mixture_gradient` non-null); false where the
/// gradient vanishes.
template <class G>
bool contact_normal(const ContactPair<G>& pair, const Vec<G::dim>* mixture_gradient, int i, Vec<G::ncomp>& n) {
  constexpr int D = G::dim;
  Vec<D> g = pair.mass_gradient[i];
  if (mixture_gradient) g -= mixture_gradient[i];
  const double gn = g.norm();
  if (!(gn > 0.0)) return false;
  n.setZero();
  n.template head<D>() = g / gn;  // Σ m_p ∇N_i(x_p) points away from the body at its boundary
  return true;
}

/// Contact impulses at one node (docs/contact.md; the algorithm is in the header comment).
/// n: unit outward normal of the solid; m_b = +∞ (std::isinf) for a prescribed body; m_s or m_f
/// = 0 for a phase absent at the node. Returns the impulses on the grains (J_s) and the fluid
/// (J_f); the solid receives −(J_s + J_f). Velocities are not modified.
template <int NC>
inline bool contact_impulses(const Vec<NC>& n, double mb, const Vec<NC>& vb, double ms, const Vec<NC>& vs, double mf,
                             const Vec<NC>& vf, double mu, Vec<NC>& Js, Vec<NC>& Jf) {
  Js.setZero();
  Jf.setZero();
  const double vbn = vb.dot(n), vsn = vs.dot(n), vfn = vf.dot(n);
  bool app_s = ms > 0.0 && vsn<vbn, app_f = mf> 0.0 && vfn < vbn;
  if (!app_s && !app_f) return false;
  const bool infinite = std::isinf(mb);
  double vn = vbn;
  if (!infinite) {
    // Common normal velocity of the solid and the approaching phases. When both approach, one
    // may end up slower (towards the solid) than the common velocity of the solid with the other
    // (a fast fluid pushing the solid away from slow grains): that phase is then not in contact;
    // dropping it lowers the mean further, so one pass settles the set.
    auto common = [&](bool s, bool f) {
      const double ps = s ? ms : 0.0, pf = f ? mf : 0.0;
      return (mb * vbn + ps * vsn + pf * vfn) / (mb + ps + pf);
    };
    vn = common(app_s, app_f);
    if (app_s && app_f) {
      if (vsn > vn) {
        app_s = false;
        vn = common(false, true);
      } else if (vfn > vn) {
        app_f = false;
        vn = common(true, false);
      }
    }
  }
  if (app_f) Jf = (mf * (vn - vfn)) * n;
  if (app_s) {
    const double Jn = ms * (vn - vsn);  // ≥ 0
    Js = Jn * n;
    if (mu > 0.0) {
      // Relative tangential velocity of the grains after the normal step (the solid's velocity
      // changed by −(J_s + J_f)/m_b).
      Vec<NC> w = vs - vb + Js / ms;
      if (!infinite) w += (Js + Jf) / mb;
      w -= w.dot(n) * n;
      const double wt = w.norm();
      if (wt > 0.0) {
        const double m_red = infinite ? ms : ms * mb / (ms + mb);
        const double Jt = std::min(mu * Jn, m_red * wt);  // slip: μ J_n; stick: m_red |w_t|
        Js -= (Jt / wt) * w;
      }
    }
  }
  return true;
}

namespace detail {
/// Weight of a node's impulse in the body sums: 0 on ghost layers behind walls (their velocities
/// are images, overwritten by the boundary conditions), ½ per wall the node lies on (the folded
/// nodal mass there is half image), 1 elsewhere (incl. ghost nodes of Open faces).
template <int D>
std::vector<double> contact_node_weights(const Grid<D>& grid, const BoundaryConditions<D>& bc) {
  std::vector<double> w(static_cast<std::size_t>(grid.node_count()), 1.0);
  for (int i = 0; i < grid.node_count(); ++i) {
    const auto s = grid.unflatten(i);
    for (int a = 0; a < D; ++a) {
      if (grid.periodic[a]) continue;
      const int l = grid.logical_index(a, s[a]);
      for (int side = 0; side < 2; ++side) {
        if (bc[2 * a + side].type == WallType::Open) continue;
        const int depth = side == 0 ? -l : l - grid.cells[a];
        if (depth > 0) w[i] = 0.0;
        if (depth == 0) w[i] *= 0.5;
      }
    }
  }
  return w;
}
}  // namespace detail

/// Volume of node i's control volume h^D (per radian: h² r_i) for the overlap test.
template <class G>
double node_measure(const Grid<G::dim>& grid, int i) {
  return G::measure(grid.node_position(i), grid.cell_volume());
}

/// One contact pair's nodes in a step: the solid's and the mixture's nodal fields and the arrays
/// of the step's contact (node weights, the mixture's nodal volume, the nodes' control volumes,
/// the mixture's mass gradient with the combined normal, else null).
template <class G>
struct ContactNodes {
  ContactPair<G>& pair;
  GridField<G>& solid;
  GridField<G>* grains;
  GridField<G>* fluid;
  const std::vector<double>& weight;
  const double* mixture_volume;
  const std::vector<double>& node_volume;
  const Vec<G::dim>* mixture_gradient;

  /// Whether node i is a contact candidate (see the header: the solid and a mixture phase have
  /// mass there, their nodal volumes overlap, the normal is defined), and its normal n.
  bool candidate(int i, Vec<G::ncomp>& n) const {
    if (!(solid.mass_kg[i] > 0.0) || weight[i] == 0.0) return false;
    const double ms = grains ? grains->mass_kg[i] : 0.0, mf = fluid ? fluid->mass_kg[i] : 0.0;
    if (!(ms > 0.0) && !(mf > 0.0)) return false;
    if (pair.overlap_threshold > 0.0 && pair.volume_m3[i] + mixture_volume[i] < pair.overlap_threshold * node_volume[i])
      return false;  // both have mass, but their smoothed volumes leave a gap: not touching
    return contact_normal(pair, mixture_gradient, i, n);
  }
};

/// A pair's sums of one step over the nodes, weighted by the node weights: this rank's share
/// (decomposed runs: its owned nodes), which the step completes over the ranks before
/// finish_pair reads it. The impulse on the solid, the part of its reaction on the grains, and the
/// count of nodes where an impulse acted.
template <class G>
struct PairSums {
  static constexpr int NC = G::ncomp;
  static constexpr std::size_t size = 2 * NC + 1;
  std::array<double, size> share{};  ///< J_body, J_grains, active nodes
  PairSums(const Vec<NC>& J_body, const Vec<NC>& J_grains, int active) {
    for (int k = 0; k < NC; ++k) {
      share[k] = J_body[k];
      share[NC + k] = J_grains[k];
    }
    share[2 * NC] = active;
  }
  explicit PairSums(const double* values) { std::copy_n(values, size, share.begin()); }
  Vec<NC> body_impulse() const { return Eigen::Map<const Vec<NC>>(share.data()); }
  Vec<NC> grains_impulse() const { return Eigen::Map<const Vec<NC>>(share.data() + NC); }
  int active_nodes() const { return static_cast<int>(share[2 * NC]); }
};

/// A pair's complete sums of the step into its outputs (force, the grains' part, active nodes, the
/// impulse sum). Returns the impulse on the solid.
template <class G>
Vec<G::ncomp> finish_pair(ContactPair<G>& pair, const PairSums<G>& sums, double dt_s) {
  Vec<G::ncomp> J = sums.body_impulse();
  pair.active_nodes = sums.active_nodes();
  pair.force_N = J / dt_s;
  pair.force_on_grains_N = sums.grains_impulse() / dt_s;
  pair.impulse_sum_N_s += J;
  return J;
}

/// Resolve one contact pair at every node (docs/contact.md): impulses applied to the nodal velocities
/// of the grains, the fluid and a deformable solid (a rigid one only accumulates them). Serial over
/// nodes (deterministic sums; the solid occupies few nodes). Returns this rank's share of the
/// pair's sums.
template <class G>
PairSums<G> resolve_contact(const ContactNodes<G>& nodes, const RigidMotion<G>& rm) {
  constexpr int NC = G::ncomp;
  GridField<G>& solid = nodes.solid;
  GridField<G>* grains = nodes.grains;
  GridField<G>* fluid = nodes.fluid;
  Vec<NC> J_body = Vec<NC>::Zero(), J_grains = Vec<NC>::Zero();
  int active = 0;
  const bool prescribed = rm.kind == BodyMotion::Prescribed, rigid = rm.rigid();
  const double mu = nodes.pair.friction_coefficient;
  const Vec<NC> zero = Vec<NC>::Zero();
  const int nn = solid.nodes();
  for (int i = 0; i < nn; ++i) {
    Vec<NC> n;
    if (!nodes.candidate(i, n)) continue;
    const double mb = solid.mass_kg[i];
    const double ms = grains ? grains->mass_kg[i] : 0.0, mf = fluid ? fluid->mass_kg[i] : 0.0;
    Vec<NC> Js, Jf;
    if (!contact_impulses<NC>(n, prescribed ? INFINITY : mb, solid.velocity[i], ms,
                              ms > 0.0 ? grains->velocity[i] : zero, mf, mf > 0.0 ? fluid->velocity[i] : zero, mu, Js,
                              Jf))
      continue;
    ++active;
    if (ms > 0.0) grains->velocity[i] += Js / ms;
    if (mf > 0.0) fluid->velocity[i] += Jf / mf;
    if (!rigid) solid.velocity[i] -= (Js + Jf) / mb;
    J_body -= nodes.weight[i] * (Js + Jf);
    J_grains += nodes.weight[i] * Js;
  }
  return {J_body, J_grains, active};
}

/// Contact of a *free rigid* body with the mixture, solved for the body as a whole (docs/contact.md, in
/// the rigid limit). Per-node two-body sharing with the body's partial nodal masses lets a rigid
/// body overtake the mixture it pushes (its fringe nodes share their velocity, the body does
/// not slow): a rod sank through a fluid that way. Here every approaching phase k at every
/// contact node i is brought to the body's normal velocity, v_k,i·n_i = V·n_i (the three-body
/// rule with the whole body as the third body), and V follows from momentum:
///   (M 1 + Σ w_i m_k,i n_i n_iᵀ) V = M V* + Σ w_i m_k,i (v_k,i·n_i) n_i   (free components),
/// with the active set (pairs with V·n_i > v_k,i·n_i, i.e. J ≥ 0) found by fixed-point iteration
/// (≤ kRigidContactPasses passes; it settles in 1–3; the step runs it: mpm/phases/contact.hpp).
/// Then Coulomb friction on the grains with the body as the infinite-mass partner,
/// J_t = min(μ J_n, m_s |w_t|), its reaction summed into V (apply_rigid_impulses). Momentum is
/// conserved exactly (each phase impulse is matched by the body's).
constexpr int kRigidContactPasses = 20;

/// The system (A, b) for V of one pass, A = M 1 + Σ w m n nᵀ and b = M V* + Σ w m (v·n) n: the
/// body's terms (body_terms) and the nodes' (add_rigid_system, this rank's share), stored as one
/// array for the ranks' completion.
template <class G>
struct RigidSystem {
  static constexpr int NC = G::ncomp;
  std::array<double, NC * NC + NC> share{};
  Eigen::Map<Mat<NC, NC>> A() { return Eigen::Map<Mat<NC, NC>>(share.data()); }
  Eigen::Map<Vec<NC>> b() { return Eigen::Map<Vec<NC>>(share.data() + NC * NC); }
  /// The body's terms alone: M 1 and M V*.
  static RigidSystem body_terms(double M, const Vec<NC>& Vstar) {
    RigidSystem s;
    s.A() = M * Mat<NC, NC>::Identity();
    s.b() = M * Vstar;
    return s;
  }
};

/// Adds this rank's nodes' terms of the rigid body's normal system at the velocity V: every phase
/// that approaches the body at a candidate node (v_k·n < V·n) with its weighted mass.
template <class G>
void add_rigid_system(const ContactNodes<G>& nodes, const Vec<G::ncomp>& V, RigidSystem<G>& sys) {
  constexpr int NC = G::ncomp;
  auto A = sys.A();
  auto b = sys.b();
  const int nn = nodes.solid.nodes();
  for (int i = 0; i < nn; ++i) {
    Vec<NC> n;
    if (!nodes.candidate(i, n)) continue;
    const double vbn = V.dot(n);
    for (GridField<G>* ph : {nodes.grains, nodes.fluid}) {
      if (!ph || !(ph->mass_kg[i] > 0.0)) continue;
      const double vkn = ph->velocity[i].dot(n);
      if (!(vkn < vbn)) continue;
      const double wm = nodes.weight[i] * ph->mass_kg[i];
      A += wm * (n * n.transpose());
      b += (wm * vkn) * n;
    }
  }
}

/// V from a complete system, the held components (free_mask 0) kept at V*.
template <class G>
Vec<G::ncomp> solve_rigid_system(RigidSystem<G> sys, const RigidMotion<G>& rm, const Vec<G::ncomp>& Vstar) {
  constexpr int NC = G::ncomp;
  Mat<NC, NC> A = sys.A();
  Vec<NC> b = sys.b();
  for (int c = 0; c < NC; ++c) {
    if (rm.free_mask[c] != 0.0) continue;
    A.row(c).setZero();
    A(c, c) = 1.0;
    b[c] = Vstar[c];
  }
  return A.partialPivLu().solve(b);
}

/// The rigid contact's impulses with the body's final velocity V: every approaching phase at every
/// candidate node brought to V·n, then friction on the grains against V. Returns this rank's share
/// of the pair's sums.
template <class G>
PairSums<G> apply_rigid_impulses(const ContactNodes<G>& nodes, const Vec<G::ncomp>& V) {
  constexpr int NC = G::ncomp;
  const double mu = nodes.pair.friction_coefficient;
  Vec<NC> J_body = Vec<NC>::Zero(), J_grains = Vec<NC>::Zero();
  int active = 0;
  const int nn = nodes.solid.nodes();
  for (int i = 0; i < nn; ++i) {
    Vec<NC> n;
    if (!nodes.candidate(i, n)) continue;
    const double vbn = V.dot(n);
    bool touched = false;
    for (GridField<G>* ph : {nodes.grains, nodes.fluid}) {
      if (!ph || !(ph->mass_kg[i] > 0.0)) continue;
      const double m = ph->mass_kg[i];
      Vec<NC>& v = ph->velocity[i];
      const double vkn = v.dot(n);
      if (!(vkn < vbn)) continue;
      touched = true;
      Vec<NC> J = (m * (vbn - vkn)) * n;
      if (ph == nodes.grains && mu > 0.0) {
        Vec<NC> w = v + J / m - V;
        w -= w.dot(n) * n;
        const double wt = w.norm();
        if (wt > 0.0) J -= (std::min(mu * (vbn - vkn) * m, m * wt) / wt) * w;
      }
      v += J / m;
      J_body -= nodes.weight[i] * J;
      if (ph == nodes.grains) J_grains += nodes.weight[i] * J;
    }
    active += touched ? 1 : 0;
  }
  return {J_body, J_grains, active};
}

/// Lattice spacing of a point of a lattice body, (V_p/measure(x_p, 1))^(1/D) (plane: √V_p;
/// axisymmetric, per radian V_p = r dx²: √(V_p/r)); not finite for a point on the axis.
template <class G>
double point_spacing(const Body<G>& body, std::int64_t p) {
  return std::pow(body.volume_m3[p] / G::measure(body.x_m[p], 1.0), 1.0 / G::dim);
}

/// Build a rigid body's cells (RigidShape) from its points.
template <class G>
void build_rigid_shape(RigidShape<G::dim>& shape, const Body<G>& body, const Grid<G::dim>& grid) {
  constexpr int D = G::dim;
  shape = RigidShape<D>();
  shape.built = true;
  const std::int64_t np = body.size();
  double dx = INFINITY;
  for (std::int64_t p = 0; p < np; ++p) {
    const double s = point_spacing(body, p);
    if (std::isfinite(s) && s > 0.0) dx = std::min(dx, s);
  }
  if (!std::isfinite(dx)) return;  // no points: nothing to keep out
  shape.dx_m = dx;
  shape.anchor_m = body.x_m[0];
  std::vector<std::array<int, D>> cells(static_cast<std::size_t>(np));
  std::array<int, D> hi{};
  for (int a = 0; a < D; ++a) {
    shape.lo[a] = std::numeric_limits<int>::max();
    hi[a] = std::numeric_limits<int>::min();
  }
  for (std::int64_t p = 0; p < np; ++p) {
    const Vec<D> d = periodic_difference<D>(grid, body.x_m[p], body.x_m[0]) / dx;
    for (int a = 0; a < D; ++a) {
      const int c = static_cast<int>(std::lround(d[a]));
      cells[static_cast<std::size_t>(p)][a] = c;
      shape.lo[a] = std::min(shape.lo[a], c);
      hi[a] = std::max(hi[a], c);
    }
  }
  std::int64_t total = 1;
  for (int a = 0; a < D; ++a) {
    shape.n[a] = hi[a] - shape.lo[a] + 1;
    total *= shape.n[a];
  }
  shape.occupied.assign(static_cast<std::size_t>(total), 0);
  for (const auto& c : cells) {
    std::int64_t k = 0;
    for (int a = 0; a < D; ++a) k = k * shape.n[a] + (c[a] - shape.lo[a]);
    shape.occupied[static_cast<std::size_t>(k)] = 1;
  }
}

/// Put the points of a mixture body that lie in a free rigid body's cells back outside it
/// (docs/contact.md, "Mixture kept out of a free rigid body"): each such point moves along the axis
/// of its shortest way out to half its own lattice spacing beyond the body's face (not out of the
/// domain on a non-periodic axis, e.g. through the axis of symmetry). Only the position changes
/// (velocity, volume and stress are the point's): no momentum is exchanged. Nodal contact
/// constrains nodal velocities only, so points near the surface, which interpolate from nodes in
/// and out of contact, and points carried by noise in the mixture, enter a rigid body and stay
/// there, adding their weight to it. Returns the number of points moved. `grid`: the global grid
/// (a decomposed run's points move across its blocks; the migration follows).
template <class G>
int keep_points_out(const RigidShape<G::dim>& shape, Body<G>& mix, const Grid<G::dim>& grid) {
  constexpr int D = G::dim;
  if (shape.occupied.empty()) return 0;
  const Vec<D> x0 = shape.anchor_m;
  const double dx = shape.dx_m;
  int moved = 0;
  const std::int64_t np = mix.size();
  for (std::int64_t p = 0; p < np; ++p) {
    const Vec<D> u = periodic_difference<D>(grid, mix.x_m[p], x0) / dx;  // in cells of the body
    std::array<int, D> c;
    bool in_box = true;
    for (int a = 0; a < D && in_box; ++a) {
      c[a] = static_cast<int>(std::lround(u[a]));
      in_box = c[a] >= shape.lo[a] && c[a] < shape.lo[a] + shape.n[a];
    }
    if (!in_box || !shape.occupied_at(c)) continue;
    const double gap = 0.5 * std::min(1.0, point_spacing(mix, p) / dx);  // (1 on the axis: not finite)
    int best_a = -1;
    double best_du = INFINITY;
    for (int a = 0; a < D; ++a)
      for (int dir = -1; dir <= 1; dir += 2) {
        std::array<int, D> e = c;
        do {
          e[a] += dir;
        } while (shape.occupied_at(e));
        const double du = (e[a] - 0.5 * dir + gap * dir) - u[a];  // to the free cell's face, + gap
        const double xa = mix.x_m[p][a] + du * dx;
        if (!grid.periodic[a] && (xa < grid.origin_m[a] || xa > grid.origin_m[a] + grid.length(a))) continue;
        if (std::fabs(du) < std::fabs(best_du)) {
          best_du = du;
          best_a = a;
        }
      }
    if (best_a < 0) continue;
    Vec<D> x = mix.x_m[p];
    x[best_a] += best_du * dx;
    grid.wrap(x);
    mix.x_m[p] = x;
    ++moved;
  }
  return moved;
}

/// Move a rigid shape's anchor with its body over the step, as move_rigid_points moves its points
/// (`grid`: the global grid).
template <class G>
void move_anchor(RigidShape<G::dim>& shape, const RigidMotion<G>& rm, const Grid<G::dim>& grid, double dt_s) {
  Vec<G::dim> x = shape.anchor_m + dt_s * rm.velocity_m_s.template head<G::dim>();
  grid.wrap(x);
  shape.anchor_m = x;
}

/// Move a rigid body's points rigidly over the step (replaces G2P): x ← x + Δt V, v ← V, C = 0,
/// L = 0 (its volume and zero stress are kept).
template <class G>
void move_rigid_points(Body<G>& body, const RigidMotion<G>& rm, const Grid<G::dim>& grid, double dt_s) {
  constexpr int D = G::dim;
  const Vec<G::ncomp> V = rm.velocity_m_s;
  const std::int64_t np = body.size();
  for (std::int64_t p = 0; p < np; ++p) {
    Vec<D> x = body.x_m[p] + dt_s * V.template head<D>();
    grid.wrap(x);
    body.x_m[p] = x;
    body.v_m_s[p] = V;
    body.C_1_s[p].setZero();
    body.L_1_s[p].setZero();
  }
}

}  // namespace oobleck::mpm
