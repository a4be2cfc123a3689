// The contract between the granular law's two forms: the batched lanes (GranularLaw::advance_batch,
// granular_batch.cpp) give the results of the scalar reference (GranularLaw::advance, granular.cpp)
// bit for bit, point by point: stress, structure f, regime, ok and gamma_dot^p. Both are built from
// the same inline point kernels (granular_kernels.hpp); a change to either file that breaks the
// equality fails here. The states cover every branch of the return map (elastic trial, f_1 + f_3
// closed form, f_1 Newton solve, separated, the p_tr <= 0 fast path and its nested fallback), the
// scalar end of step (implicit structure update, forced f = 1, unconverged return maps), invalid
// inputs, overflow, and the in-plane trials.
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "oobleck/material/granular.hpp"
#include "test_helpers.hpp"

using namespace oobleck;
using material::GranularRegime;
using test::log_uniform;
using test::random_tensor;

namespace {

/// The n doubles at a and at b are the same bit for bit (signs of zeros and NaN payloads included).
bool same_bits(const double* a, const double* b, int n) {
  for (int i = 0; i < n; ++i) {
    if (std::bit_cast<std::uint64_t>(a[i]) != std::bit_cast<std::uint64_t>(b[i])) return false;
  }
  return true;
}

// advance_batch (the MPM adapter's call: Newton solves in lanes across points) must give the
// results of advance() point by point, bit for bit, in every regime and on failures: random
// states as in the sweep above (one dt per batch), a loose bed as in the bench set-ups, and a few
// invalid inputs (non-finite L, phi outside (0, 1)).
// `options` other than the defaults: exactly the three invalid inputs fail only with the defaults
// (a small max_iter makes some return maps stop unconverged, `not_ok` then counts those too).
// `plane`: sigma and L without xz, yz entries, and advance_batch's in-plane trials (plane strain;
// with `detect`, not asked for: advance_batch finds the blocks in plane motion itself); a zero
// entry may then differ in its sign only.
void batch_equals_point_by_point(const std::string& preset_name, std::uint64_t seed, double dt, bool loose,
                                 material::GranularOptions options = {}, bool plane = false, bool detect = false) {
  const rheology::Preset P = test::preset(preset_name);
  const material::GranularLaw law(P, options);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  const int n = 3000;
  std::vector<Eigen::Matrix3d> sigma(n), L(n);
  std::vector<double> f(n), phi(n);
  for (int k = 0; k < n; ++k) {
    phi[k] = loose ? 0.47 + 0.02 * U(rng) : 0.3 + 0.3 * U(rng);
    f[k] = loose ? (U(rng) < 0.2 ? 0.0 : log_uniform(rng, 1e-22, 1e-3)) : U(rng);
    const double p = (U(rng) < (loose ? 0.5 : 0.2) ? -1.0 : 1.0) *
                     (loose ? log_uniform(rng, 1e-12, 1e-2) : log_uniform(rng, 1e-3, 1e6));
    Eigen::Matrix3d s = random_tensor(rng, 1.0);
    s = 0.5 * (s + s.transpose()).eval();
    s.diagonal().array() -= s.trace() / 3.0;
    sigma[k] = std::sqrt(2.0) * (0.1 + 3.0 * U(rng)) * std::fabs(p) * s / s.norm();
    sigma[k].diagonal().array() -= p;
    L[k] = random_tensor(rng, loose ? log_uniform(rng, 1e-5, 1e-1) : log_uniform(rng, 1e-3, 1e4));
  }
  L[7](0, 1) = std::numeric_limits<double>::quiet_NaN();  // invalid inputs: reported, state kept
  phi[11] = 1.0;
  phi[2999] = 0.0;
  // edge points: a stress-free point at rest (p_tr = -0, tau_tr = 0: the separated form, regime
  // elastic), isotropic compression at rest above phi_j (elastic trial with tau_tr = 0), phi on
  // phi_m(f) exactly (u_eq = 0), and stresses near the largest double (the trial overflows: the
  // scalar end of step)
  sigma[20].setZero();
  L[20].setZero();
  sigma[21] = -1e3 * Eigen::Matrix3d::Identity();
  L[21].setZero();
  phi[21] = 0.6;
  f[22] = 0.0;
  phi[22] = P.steady.phi_j;
  sigma[23] *= 1e307 / sigma[23].cwiseAbs().maxCoeff();
  if (plane) {  // (after the edge points: the scaling of point 23 may overflow to inf)
    for (int k = 0; k < n; ++k)
      for (int e : {2, 5, 6, 7}) sigma[k].data()[e] = L[k].data()[e] = 0.0;
  }
  std::vector<Eigen::Matrix3d> sigma_b = sigma, sigma_p = sigma;
  std::vector<double> f_b = f, f_p = f;
  std::vector<material::GranularStep> step_b(n), step_p(n);
  law.advance_batch(n, sigma_b.data(), f_b.data(), L.data(), phi.data(), dt, step_b.data(), plane && !detect);
  int counts[5] = {0, 0, 0, 0, 0}, mismatches = 0, not_ok = 0;
  int f1_solves = 0, tension_solves = 0, implicit = 0;
  for (int k = 0; k < n; ++k) {
    Eigen::Matrix3d D, W;
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) {
        D(i, j) = 0.5 * (L[k](i, j) + L[k](j, i));
        W(i, j) = 0.5 * (L[k](i, j) - L[k](j, i));
      }
    {  // which path of the return map the point takes (update()'s diagnostics on a copy)
      material::GranularState probe{sigma_p[k], f_p[k]};
      const material::GranularUpdate u = law.update(probe, D, W, dt, phi[k]);
      const bool sheared = u.regime == GranularRegime::kShear;
      f1_solves += sheared && u.p_trial > 0.0 ? 1 : 0;
      tension_solves += sheared && u.p_trial <= 0.0 ? 1 : 0;
      implicit += u.structure_iterations > 0 ? 1 : 0;
    }
    material::GranularState st{sigma_p[k], f_p[k]};
    step_p[k] = law.advance(st, D, W, dt, phi[k]);
    if (step_p[k].ok) {
      sigma_p[k] = st.sigma;
      f_p[k] = st.f;
    }
    counts[static_cast<int>(step_p[k].regime)]++;
    not_ok += step_p[k].ok ? 0 : 1;
    if (plane) {
      for (int e : {2, 5, 6, 7}) {
        EXPECT_EQ(sigma_b[k].data()[e], 0.0) << "point " << k;
        EXPECT_EQ(sigma_p[k].data()[e], 0.0) << "point " << k;
        sigma_b[k].data()[e] = sigma_p[k].data()[e] = 0.0;  // +0 both (the sign of a zero may differ)
      }
    }
    const bool same = same_bits(sigma_b[k].data(), sigma_p[k].data(), 9) && same_bits(&f_b[k], &f_p[k], 1) &&
                      step_b[k].ok == step_p[k].ok && step_b[k].regime == step_p[k].regime &&
                      same_bits(&step_b[k].gamma_dot_p, &step_p[k].gamma_dot_p, 1);
    if (!same && ++mismatches <= 5)
      ADD_FAILURE() << "point " << k << ": batch and point-by-point results differ (phi = " << phi[k] << ")";
  }
  EXPECT_EQ(mismatches, 0);
  std::printf("%s seed %llu: f_1 solves %d, p_tr <= 0 solves %d, implicit structure %d, not ok %d\n",
              preset_name.c_str(), static_cast<unsigned long long>(seed), f1_solves, tension_solves, implicit, not_ok);
  const bool defaults = options.max_iter == material::GranularOptions{}.max_iter;
  if (defaults) {
    EXPECT_EQ(not_ok, 3 + (step_p[23].ok ? 0 : 1));  // the three invalid inputs (and the overflow)
  } else {
    EXPECT_GT(not_ok, 3);  // the cap stopped some return maps
  }
  // both Newton solves that run in lanes (and, unless staggered, the scalar implicit structure
  // update) must have been met
  EXPECT_GT(f1_solves, 20);
  EXPECT_GT(tension_solves, 100);
  if (!loose && options.structure_update != material::StructureUpdate::kStaggered) {
    EXPECT_GT(implicit, n / 20);
  }
  // the batch must have met the regimes whose Newton solves it runs in lanes
  EXPECT_GT(counts[static_cast<int>(GranularRegime::kShear)], n / 20);
  EXPECT_GT(counts[static_cast<int>(GranularRegime::kShearCompaction)] +
                counts[static_cast<int>(GranularRegime::kCompaction)],
            n / 20);
  if (!loose) {
    EXPECT_GT(counts[static_cast<int>(GranularRegime::kSeparated)], 5);
  }
}

}  // namespace

TEST(GranularBatchContract, RandomStates) {
  batch_equals_point_by_point("hermes2016", 99, 1e-5, false);
  batch_equals_point_by_point("dhaene1993", 98, 1e-3, false);
}
// The structure-update and jammed-structure options, whose points take finish() itself in
// advance_batch (implicit update, forced f = 1), and unconverged return maps (iteration cap).
TEST(GranularBatchContract, StructureAndIterationOptions) {
  material::GranularOptions implicit;
  implicit.structure_update = material::StructureUpdate::kImplicit;
  batch_equals_point_by_point("hermes2016", 95, 1e-5, false, implicit);
  material::GranularOptions staggered;
  staggered.structure_update = material::StructureUpdate::kStaggered;
  batch_equals_point_by_point("hermes2016", 94, 1e-5, false, staggered);
  material::GranularOptions forced;
  forced.jammed_structure = material::JammedStructure::kForceOne;
  batch_equals_point_by_point("hermes2016", 93, 1e-5, false, forced);
  material::GranularOptions capped;
  capped.max_iter = 5;
  batch_equals_point_by_point("hermes2016", 92, 1e-5, false, capped);
}
TEST(GranularBatchContract, LooseBed) {
  batch_equals_point_by_point("hermes2016", 97, 2e-5, true);
  batch_equals_point_by_point("hermes2016", 96, 1e-6, true);
}
// The in-plane trials (advance_batch's in_plane: the plane-strain adapter's call) on plane states:
// random, a loose bed, and an option whose points take finish() itself.
TEST(GranularBatchContract, InPlaneTrials) {
  batch_equals_point_by_point("hermes2016", 91, 1e-5, false, {}, true);
  batch_equals_point_by_point("dhaene1993", 90, 1e-3, false, {}, true);
  batch_equals_point_by_point("hermes2016", 89, 2e-5, true, {}, true);
  material::GranularOptions implicit;
  implicit.structure_update = material::StructureUpdate::kImplicit;
  batch_equals_point_by_point("hermes2016", 88, 1e-5, false, implicit, true);
  batch_equals_point_by_point("hermes2016", 87, 1e-5, false, {}, true, true);  // blocks found in plane motion
}
