#pragma once
// The registry of persistent fields: every array that a restart needs or that the frames show is
// declared once, by its owner, as a PersistentField in a FieldList. Checkpoint write and restore
// (run/checkpoint_state.cpp) and the frames (run/run_output.cpp) iterate that list; none of them
// names a field.
//
// Owners and their declarations:
//   Body<G>::declare_fields          the point arrays of every body (group "body<b>")
//   StressLaw<G>::declare_fields     a law's per-point state (GranularBodyLaw: group "granular",
//                                    FluidLaw: "fluid") and what it adds to its body's frames
//   RigidMotion / ContactPair        a [[body]] entry's rigid velocity and contact impulse sum
//   (via run/checkpoint_state.cpp)   (group "third<k>")
//   Solver<G>::declare_grid_fields   nodal arrays the frames show on the grid (group "grid")
//   run::SceneAnalysis::declare_fields, run::Snapshots::declare_fields
//                                    a scene measurement's samples (group "analysis") and its
//                                    counters (checkpoint attributes)
// Beside them, NodalFieldList registers the step's nodal arrays (not persistent) with how a
// decomposed run's halo treats each (HaloRule): the exchanges' lists are generated from it.
// A checkpoint dataset is "GROUP/NAME", an attribute is NAME; a frame field is NAME (or
// frame_name) of its body, or of the grid.
#include <cstddef>
#include <cstdint>
#include <algorithm>
#include <functional>
#include <initializer_list>
#include <span>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

namespace oobleck::mpm {

/// How a field appears in the frames (io/frames.hpp): not at all, as the body's positions, as a
/// scalar, a vector (width 2 or 3), a symmetric tensor (width 9, a 3×3 matrix in Eigen's
/// column-major order; the frame shows xx xy xz yy yz zz), or a scalar on the grid's physical
/// nodes (the array in the grid's storage order, run/run_output.cpp maps it).
enum class FrameForm { none, position, scalar, vector, sym_tensor, node_scalar };

/// A series that grows during a run (a scene analysis's samples), checkpointed flat: `pack`
/// gives its values, `unpack` replaces the series with a checkpoint's. Written when not empty,
/// read when the checkpoint has it (a run that had not sampled it yet).
struct GrowingSeries {
  std::function<std::vector<double>()> pack;
  std::function<void(const std::vector<double>&)> unpack;
};

/// One named array, `width` values per item, viewed in place (no copy).
struct PersistentField {
  std::string group;  ///< checkpoint group: "body0", "granular", "fluid", "third0", "analysis"
  std::string name;   ///< the dataset under the group ("x", "ln_J"), or the attribute's name;
                      ///< also the frame name
  int width = 1;      ///< values per item (the dataset is stored flat: items × width)
  const char* unit = "1";
  /// The values, read for checkpoints and frames and written on restore: a fixed-size array
  /// (span), a growing series, or one number stored as a checkpoint attribute (double* or
  /// std::int64_t*). Empty (monostate) for a field the frames derive (`derive`).
  std::variant<std::monostate, std::span<double>, std::span<std::uint8_t>, GrowingSeries, double*, std::int64_t*> data;
  bool in_checkpoint = true;
  FrameForm frame = FrameForm::none;
  std::string frame_name;    ///< the frame's name when it differs from `name`
  int frame_rank = 1 << 20;  ///< frames show fields by rank, then in declaration order
  /// Frame-only field: fill one value per item (called when a frame is written).
  std::function<void(std::span<double>)> derive;
  /// Older checkpoints that stored this field as `legacy_name` (read when `name` is absent;
  /// in the field's group, or "/GROUP/NAME" in another), converted value by value with
  /// `from_legacy`.
  std::string legacy_name;
  double (*from_legacy)(double) = nullptr;
  /// One item per point of a body (FieldList::add): a decomposed run's ranks each hold their own
  /// points' items, and write them to a checkpoint together (io::CheckpointWriter::ranks_array).
  bool per_point = false;

  bool is_attribute() const {
    return std::holds_alternative<double*>(data) || std::holds_alternative<std::int64_t*>(data);
  }
  /// The checkpoint's name: "GROUP/NAME" for a dataset, NAME for an attribute.
  std::string dataset() const { return is_attribute() ? name : group + "/" + name; }
  const std::string& shown_as() const { return frame_name.empty() ? name : frame_name; }
};

/// Values per element: 1 for a double, the size of a fixed-size Eigen vector or matrix.
template <class T>
constexpr int element_width() {
  if constexpr (std::is_same_v<T, double>)
    return 1;
  else
    return static_cast<int>(T::SizeAtCompileTime);
}

/// View a vector of fixed-size Eigen objects (or doubles) as doubles (stored without padding).
template <class T>
std::span<double> flat_doubles(std::vector<T>& v) {
  if constexpr (std::is_same_v<T, double>) {
    return {v.data(), v.size()};
  } else {
    static_assert(sizeof(T) == sizeof(double) * T::SizeAtCompileTime, "padded Eigen type");
    return {reinterpret_cast<double*>(v.data()), v.size() * static_cast<std::size_t>(T::SizeAtCompileTime)};
  }
}

/// A nodal array of the local grid: `width` doubles per node.
struct NodalArray {
  double* data = nullptr;
  int width = 1;
};

template <class T>
NodalArray nodal(std::vector<T>& v) {
  return {flat_doubles(v).data(), element_width<T>()};
}

/// How a decomposed run's halo (halo.hpp, docs/mpi.md) treats a nodal array, and at which of the
/// step's exchanges (step.hpp; phase numbers of docs/mpm.md).
enum class HaloRule {
  none,                ///< not exchanged (each rank's own values, or recomputed on every node)
  sum_after_p2g,       ///< partial sums added into the owners' nodes after P2G (phase 2)
  sum_before_contact,  ///< contact's partial sums added into the owners' nodes before the impulses (phase 4)
  copy_before_flux,    ///< the owners' values copied out to the neighbours' copies after the walls (phase 5)
};

/// True for the rules whose exchange adds partial sums into the owners (Halo::sum).
constexpr bool sums_to_owners(HaloRule rule) {
  return rule == HaloRule::sum_after_p2g || rule == HaloRule::sum_before_contact;
}

/// One nodal array of the step and its halo rule.
struct NodalField {
  const char* name = "";
  NodalArray array;
  HaloRule halo = HaloRule::none;
};

/// The registry of the step's nodal arrays (SolverState::nodal_fields): each declared once, by
/// its owner (GridField<G>::declare_nodal_fields, ContactPair<G>::declare_nodal_fields, the
/// solver's mixture arrays), with its halo rule. A halo exchange takes its list from here.
class NodalFieldList {
 public:
  template <class T>
  void add(const char* name, std::vector<T>& v, HaloRule halo) {
    fields_.push_back({name, nodal(v), halo});
  }
  /// The arrays of one exchange, in declaration order.
  std::vector<NodalArray> exchanged(HaloRule rule) const {
    std::vector<NodalArray> arrays;
    for (const auto& f : fields_)
      if (f.halo == rule) arrays.push_back(f.array);
    return arrays;
  }
  const std::vector<NodalField>& fields() const { return fields_; }

 private:
  std::vector<NodalField> fields_;
};

/// The declarations of one or more owners, in declaration order (the frames' order).
class FieldList {
 public:
  /// Following declarations belong to checkpoint group `g`.
  void group(std::string g) { group_ = std::move(g); }

  /// A per-point array of doubles or Eigen vectors/matrices; width from the element type. Shown
  /// in the frames as `frame` (under `frame_name` if not empty); `legacy_name`, `from_legacy`:
  /// see PersistentField.
  template <class T>
  PersistentField& add(std::string name, std::vector<T>& v, const char* unit, FrameForm frame = FrameForm::none,
                       std::string frame_name = {}, std::string legacy_name = {},
                       double (*from_legacy)(double) = nullptr) {
    return push({group_,
                 std::move(name),
                 element_width<T>(),
                 unit,
                 flat_doubles(v),
                 true,
                 frame,
                 std::move(frame_name),
                 1 << 20,
                 {},
                 std::move(legacy_name),
                 from_legacy,
                 true});
  }
  PersistentField& add(std::string name, std::vector<std::uint8_t>& v, const char* unit,
                       FrameForm frame = FrameForm::none) {
    return push({group_,
                 std::move(name),
                 1,
                 unit,
                 std::span<std::uint8_t>(v),
                 true,
                 frame,
                 {},
                 1 << 20,
                 {},
                 {},
                 nullptr,
                 true});
  }
  /// A fixed-size array of `width` doubles (one item; e.g. a rigid body's velocity).
  PersistentField& add_values(std::string name, std::span<double> values, const char* unit) {
    const int width = static_cast<int>(values.size());
    return push(
        {group_, std::move(name), width, unit, values, true, FrameForm::none, {}, 1 << 20, {}, {}, nullptr, false});
  }
  /// A series that grows during the run (see GrowingSeries).
  PersistentField& add_series(std::string name, const char* unit, std::function<std::vector<double>()> pack,
                              std::function<void(const std::vector<double>&)> unpack) {
    return push({group_,
                 std::move(name),
                 1,
                 unit,
                 GrowingSeries{std::move(pack), std::move(unpack)},
                 true,
                 FrameForm::none,
                 {},
                 1 << 20,
                 {},
                 {},
                 nullptr,
                 false});
  }
  /// One number, stored as a checkpoint attribute.
  PersistentField& add_attribute(std::string name, double& value, const char* unit) {
    return push({group_, std::move(name), 1, unit, &value, true, FrameForm::none, {}, 1 << 20, {}, {}, nullptr, false});
  }
  PersistentField& add_attribute(std::string name, std::int64_t& value, const char* unit) {
    return push({group_, std::move(name), 1, unit, &value, true, FrameForm::none, {}, 1 << 20, {}, {}, nullptr, false});
  }
  /// A nodal array (grid storage order) the frames show on the physical nodes (not in
  /// checkpoints: the step recomputes it).
  PersistentField& add_nodal(std::string name, std::span<double> nodes, const char* unit) {
    return push(
        {group_, std::move(name), 1, unit, nodes, false, FrameForm::node_scalar, {}, 1 << 20, {}, {}, nullptr, false});
  }
  /// A scalar the frames compute from other fields (not in checkpoints).
  PersistentField& derived(std::string name, const char* unit, std::function<void(std::span<double>)> fill) {
    return push({group_,
                 std::move(name),
                 1,
                 unit,
                 {},
                 false,
                 FrameForm::scalar,
                 {},
                 1 << 20,
                 std::move(fill),
                 {},
                 nullptr,
                 false});
  }
  /// Show an already declared field of the current group in the frames, as `form`, under
  /// `frame_name` if given (e.g. the fluid law shows its body's phi, and its pressure as
  /// "fluid_pressure").
  void show(const std::string& name, FrameForm form, std::string frame_name = {}) {
    for (auto& f : fields_) {
      if (f.group != group_ || f.name != name) continue;
      f.frame = form;
      f.frame_name = std::move(frame_name);
      return;
    }
  }

  /// The frames show these fields of the current group first, in this order (then the others
  /// in declaration order).
  void frame_order(std::initializer_list<const char*> names) {
    int rank = 0;
    for (const char* n : names) {
      for (auto& f : fields_)
        if (f.group == group_ && f.name == n) f.frame_rank = rank;
      ++rank;
    }
  }

  /// In declaration order (the checkpoints' order).
  const std::vector<PersistentField>& fields() const { return fields_; }
  /// The fields the frames show, in the frames' order.
  std::vector<const PersistentField*> frame_fields() const {
    std::vector<const PersistentField*> shown;
    for (const auto& f : fields_)
      if (f.frame != FrameForm::none) shown.push_back(&f);
    std::stable_sort(shown.begin(), shown.end(), [](auto* a, auto* b) { return a->frame_rank < b->frame_rank; });
    return shown;
  }

 private:
  PersistentField& push(PersistentField f) {
    fields_.push_back(std::move(f));
    return fields_.back();
  }
  std::string group_;
  std::vector<PersistentField> fields_;
};

}  // namespace oobleck::mpm
