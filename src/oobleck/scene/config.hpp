#pragma once
// A scene file (TOML) as typed, validated data: geometry, suspension material, fluid, coupling,
// transfer scheme, regions of material points, boundaries, gravity, time stepping and output.
// Every key is named with its unit in docs/scenes.md; unknown keys are errors with a suggestion.
// This layer knows nothing of the solver; scene/build.* turns a SceneConfig into bodies.
#include <array>
#include <cmath>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "oobleck/rheology/params.hpp"

namespace oobleck::scene {

enum class Geometry { PlaneStrain, Axisymmetric, ThreeD };
enum class ShapeKind { Linear, Quadratic, Cubic, UGimp };
enum class TransferScheme { Apic, Flip };
enum class DragLaw { Beetstra, CarmanKozeny };
enum class Phase { Mixture, Fluid, Grains, Elastic };
enum class InitialState { AtRest, Hydrostatic, Suspended };
enum class BoundaryType { NoSlip, Slip, Friction, Velocity, Periodic, Open, Axis };

const char* to_string(Geometry g);
const char* to_string(ShapeKind s);
const char* to_string(BoundaryType b);
const char* to_string(Phase p);

struct GridConfig {
  Geometry geometry = Geometry::PlaneStrain;
  int dim = 2;                              ///< 2 (plane strain, axisymmetric) or 3
  std::array<double, 3> origin_m{0, 0, 0};  ///< [m] lower corner (axisymmetric: (r_0, z_0))
  std::array<double, 3> size_m{0, 0, 0};    ///< [m] domain extent per axis
  double cell_size_m = 0.0;                 ///< [m] h
  std::array<int, 3> cells{1, 1, 1};        ///< derived: size/h (must be an integer)
  ShapeKind shape = ShapeKind::Quadratic;
  /// [-] linear kernels: nodal mass floor as a fraction of a full node's mass (mpm::SolverOptions::
  /// linear_mass_floor); unset: (Δt/Δt_crit)², i.e. cfl². 0 turns it off.
  std::optional<double> linear_mass_floor;
};

/// [fluid]: rho_f, kappa, eta_0 (rheology/parameter_table.cpp); eta_0 defaults to the material's.
using FluidConfig = rheology::FluidParams;

struct CouplingConfig {
  DragLaw drag = DragLaw::Beetstra;
  double porosity_min = 0.2;  ///< [-] lower clamp of nodal porosity n (E28, docs/equations.md)
};

struct TransferConfig {
  TransferScheme scheme = TransferScheme::Apic;
  double flip_fraction = 0.99;  ///< FLIP/PIC blend for scheme = "flip" (1 = pure FLIP)
};

struct ElasticConfig {
  double density_kg_m3 = 0.0;
  double youngs_modulus_Pa = 0.0;
  double poisson_ratio = 0.0;
};

/// A region of the domain filled with material points.
struct RegionConfig {
  std::string name;
  Phase phase = Phase::Mixture;
  std::array<double, 3> min_m{0, 0, 0}, max_m{0, 0, 0};  ///< [m] box corners
  double phi = 0.0;                                      ///< [-] granular volume fraction (mixture/grains)
  int points_per_cell = 2;                               ///< per axis and per phase
  std::array<double, 3> velocity_m_s{0, 0, 0};  ///< [m/s] initial velocity (3 comps; v_theta third in axisymmetric)
  InitialState initial_state = InitialState::AtRest;
  ElasticConfig elastic;  ///< for phase = "elastic"
};

/// Shape of a third body (docs/contact.md). Axisymmetric: a box touching r = 0 is a cylinder.
enum class BodyShape { Box, Disc, Wheel, Cylinder };
/// How a third body moves: rigid at a fixed velocity (intruder), free rigid translation under
/// gravity and contact (rod), or elastic (wheel; optionally with a motor on its mean ω).
enum class BodyMotionKind { Prescribed, Free, Elastic };

/// A solid third body in contact with the mixture ([[body]] in a scene file).
struct BodyConfig {
  std::string name;
  BodyShape shape = BodyShape::Box;
  std::array<double, 3> min_m{0, 0, 0}, max_m{0, 0, 0};  ///< [m] box corners (shape = "box")
  std::array<double, 3> centre_m{0, 0, 0};  ///< [m] centre (disc, wheel); cylinder: its bottom face's centre
  double radius_m = 0.0;                    ///< [m] disc or cylinder radius
  double length_m = 0.0;                    ///< [m] cylinder length along its axis
  double tilt_deg = 0.0;         ///< [deg] cylinder: its axis and velocity turned from the vertical towards +x
  double hub_radius_m = 0.0;     ///< [m] wheel hub radius
  double paddle_length_m = 0.0;  ///< [m] paddle length beyond the hub (tip radius = hub + paddle)
  double paddle_width_m = 0.0;   ///< [m] paddle width
  int paddles = 4;               ///< number of paddles (spokes)
  double width_m = 0.0;          ///< [m] disc or wheel on a 3D grid: its extent along y (its axle)
  double angle_deg = 0.0;        ///< [deg] angle of the first paddle from +x
  BodyMotionKind motion = BodyMotionKind::Prescribed;
  std::array<double, 3> velocity_m_s{0, 0,
                                     0};  ///< [m/s] prescribed (or initial) velocity (scaled to `speed` when given)
  double ramp_time_s =
      0.0;  ///< [s] prescribed: speed rises linearly from 0 to |velocity| over this time (0: full speed from t = 0)
  double density_kg_m3 = 0.0;               ///< [kg/m^3]
  std::optional<double> mass_kg;            ///< [kg] whole-body mass (rigid free bodies; sets the density)
  double youngs_modulus_Pa = 0.0;           ///< [Pa] elastic bodies
  double poisson_ratio = 0.3;               ///< [-] elastic bodies
  int points_per_cell = 2;                  ///< per axis
  double friction = 0.0;                    ///< [-] Coulomb coefficient between body and grains
  std::optional<double> motor_omega_rad_s;  ///< [rad/s] motor target ω (elastic; plane strain or 3D)
  double motor_gain = 1.0;                  ///< [-] fraction of the ω error removed per step
};

/// A cylinder's frame ([[body]] shape = "cylinder", 3D grids; z is vertical): its unit axis,
/// turned by `tilt` from +z towards +x about the y axis, and the centre of its bottom face, raised
/// by radius |sin(tilt)| above `centre` so that the lowest point of the bottom rim stays at
/// `centre`'s height. The body is the set of x with 0 <= (x - base).axis <= length and distance
/// from the axis <= radius.
struct CylinderFrame {
  std::array<double, 3> axis{0, 0, 1};    ///< unit vector from the bottom face to the top face
  std::array<double, 3> base_m{0, 0, 0};  ///< [m] centre of the bottom face
  /// [m] the bounding box of the two end discs
  std::array<double, 3> lo_m{0, 0, 0}, hi_m{0, 0, 0};
};
CylinderFrame cylinder_frame(const BodyConfig& b);

struct BoundaryConfig {
  BoundaryType type = BoundaryType::NoSlip;
  double friction = 0.0;                        ///< Coulomb coefficient (type = friction)
  std::array<double, 3> velocity_m_s{0, 0, 0};  ///< prescribed velocity (type = velocity)
};

struct TimeConfig {
  double duration_s = 0.0;     ///< [s] simulated time
  std::optional<double> dt_s;  ///< [s] user time step (refused above the stable one)
  double cfl = 0.4;            ///< fraction of the stable time step used by default
};

struct OutputConfig {
  double frame_interval_s = 0.0;   ///< [s] HDF5 frame interval (0: first and last only)
  double series_interval_s = 0.0;  ///< [s] CSV series interval (0: every 100 steps)
  long checkpoint_every = 0;       ///< steps between checkpoints (0: none)
};

/// Built-in measurement written into summary.json (scenes/verification).
enum class AnalysisKind { None, Settling, Couette, Annular, Intrusion, Rod, Wheel };

struct AnalysisConfig {
  AnalysisKind kind = AnalysisKind::None;
  double average_from_s = 0.0;   ///< [s] start of the time average (settling)
  double sample_interval_s = 0;  ///< [s] nodal-field sampling interval (annular; 0: duration/200)
  double sample_z_m = NAN;  ///< [m] height of the surface profile line (annular; default 2 cells below the bed top)
  std::string body;         ///< body analysed (intrusion, rod, wheel; default: the first [[body]])
  double filter_window_s = 0.0;  ///< [s] intrusion: moving time average of the sampled fields; rod: finite-difference
                                 ///< stencil (0: one sample)
  double front_fraction = 0.5;   ///< [-] velocity front at u_z = fraction v_0 (intrusion)
  double f_threshold = 0.5;      ///< [-] structure front at f = threshold (intrusion)
  /// [s] times of nodal-field snapshots written as snapshot_<k>.csv (2D grids): intrusion u_z
  /// (6.2, 13.2, 20 ms), rod displacement (60 ms), wheel pressure (1 s)
  std::vector<double> snapshot_times_s;
};

const char* to_string(BodyMotionKind m);
const char* to_string(AnalysisKind k);

struct SceneConfig {
  std::string file;
  std::string resolved_toml;  ///< the scene after --set overrides (stored with runs, for --restart)
  std::string name;
  std::string description;
  GridConfig grid;
  rheology::Preset material;  ///< suspension parameters (preset + overrides)
  FluidConfig fluid;
  CouplingConfig coupling;
  TransferConfig transfer;
  std::vector<RegionConfig> regions;
  std::vector<BodyConfig> bodies;
  std::array<BoundaryConfig, 6> boundary;  ///< x_min, x_max, y_min, y_max, z_min, z_max
  std::array<double, 3> gravity_m_s2{0, 0, 0};
  TimeConfig time;
  OutputConfig output;
  AnalysisConfig analysis;
  std::map<std::string, std::string> aliases;  ///< short --set names -> full key paths
};

/// Face names in the order of SceneConfig::boundary.
const std::array<const char*, 6>& face_names();

/// Parse and validate a scene file. `overrides` are "key.path=value" strings (--set); a key may
/// be a full dotted path ("region.0.phi" or "grid.cell_size") or an alias declared in the scene's
/// [aliases] table. Values are parsed as TOML values (numbers, strings in quotes or bare words).
SceneConfig load_scene(const std::string& path, const std::vector<std::string>& overrides = {});

/// The key path an override `key=value` (or `alias=value`) sets, after the scene's [aliases];
/// InputError when `spec` has no `=`.
std::string override_key(const std::string& spec, const std::map<std::string, std::string>& aliases);

}  // namespace oobleck::scene
