#pragma once
// The exchanges of a decomposed run (docs/mpi.md, decomposition.hpp): nodal sums to their owners
// after P2G, owners' nodal values out to the neighbours' copies before G2P, and the points that
// crossed a block face to their new owner after the step.
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "oobleck/core/comm.hpp"
#include "oobleck/mpm/body.hpp"
#include "oobleck/mpm/decomposition.hpp"
#include "oobleck/mpm/fields.hpp"
#include "oobleck/mpm/grid.hpp"

namespace oobleck::mpm {

template <int D>
class Halo {
 public:
  Halo(const Decomposition<D>& decomposition, const Grid<D>& local) : dec_(decomposition), grid_(local) {}

  /// Owners add the partial sums their neighbours hold on the owners' nodes (after P2G).
  void sum(std::span<const NodalArray> arrays) {
    const int kG = Grid<D>::kGhost;
    for (int a = 0; a < D; ++a) {
      if (!dec_.split(a)) continue;
      const int n = grid_.cells[a];
      // upward: my l in [n, n+3) onto the upper neighbour's [0, 3); downward: my [−2, 0) onto the
      // lower neighbour's [n' − 2, n')
      exchange(a, arrays, n + kG, kG + 1, kG, /*upward*/ true, /*add*/ true, 2 * a);
      exchange(a, arrays, 0, kG, n, /*upward*/ false, /*add*/ true, 2 * a + 1);
    }
  }

  /// Owners' values out to the neighbours' copies of their nodes (before G2P).
  void copy(std::span<const NodalArray> arrays) {
    const int kG = Grid<D>::kGhost;
    for (int a = 0; a < D; ++a) {
      if (!dec_.split(a)) continue;
      const int n = grid_.cells[a];
      // upward: my l in [n−2, n) onto the upper neighbour's [−2, 0); downward: my [0, 3) onto the
      // lower neighbour's [n', n' + 3)
      exchange(a, arrays, n, kG, 0, /*upward*/ true, /*add*/ false, 2 * a);
      exchange(a, arrays, kG, kG + 1, n + kG, /*upward*/ false, /*add*/ false, 2 * a + 1);
    }
  }

  /// The exchange of `rule` (fields.hpp) over `arrays`: sum() or copy().
  void apply(HaloRule rule, std::span<const NodalArray> arrays) {
    if (sums_to_owners(rule))
      sum(arrays);
    else if (rule == HaloRule::copy_before_flux)
      copy(arrays);
  }

  /// Bytes this rank sent in the exchanges so far.
  std::int64_t bytes_sent() const { return bytes_sent_; }

 private:
  /// Send the storage layers [s_send, s_send + layers) along axis a to the neighbour on side
  /// `upward`, receive the same number of layers from the opposite neighbour into storage layers
  /// starting at s_recv_lo (the receiver's `n` differs from the sender's: the receive layer is
  /// given in the receiver's terms: for the downward sum and the upward copy the first layers,
  /// otherwise counted from its own n).
  void exchange(int a, std::span<const NodalArray> arrays, int s_send, int layers, int s_recv, bool upward, bool add,
                int tag) {
    const int to = dec_.neighbour(a, upward), from = dec_.neighbour(a, !upward);
    if (to < 0 && from < 0) return;
    int per_node = 0;
    for (const auto& arr : arrays) per_node += arr.width;
    const int na = grid_.nodes(a), st = grid_.stride(a);
    const int outer = grid_.node_count() / (na * st);
    const std::size_t count = static_cast<std::size_t>(outer) * layers * st * per_node;
    send_.resize(to >= 0 ? count : 0);
    recv_.resize(from >= 0 ? count : 0);
    // f(value, k) for the k-th value of the slab's layers [s0, s0 + layers) (node by node, the
    // arrays in order)
    auto for_slab = [&](int s0, auto&& f) {
      std::size_t k = 0;
      for (int o = 0; o < outer; ++o)
        for (int s = s0; s < s0 + layers; ++s)
          for (int i = 0; i < st; ++i) {
            const std::size_t node = (static_cast<std::size_t>(o) * na + s) * st + i;
            for (const auto& arr : arrays)
              for (int w = 0; w < arr.width; ++w) f(arr.data[node * arr.width + w], k++);
          }
    };
    if (to >= 0) {
      for_slab(s_send, [&](double v, std::size_t k) { send_[k] = v; });
      bytes_sent_ += static_cast<std::int64_t>(count * sizeof(double));
    }
    comm::sendrecv(send_, to, recv_, from, tag);
    if (from < 0) return;
    if (add)
      for_slab(s_recv, [&](double& v, std::size_t k) { v += recv_[k]; });
    else
      for_slab(s_recv, [&](double& v, std::size_t k) { v = recv_[k]; });
  }

  const Decomposition<D>& dec_;
  Grid<D> grid_;
  std::vector<double> send_, recv_;
  std::int64_t bytes_sent_ = 0;
};

namespace detail {
/// The body's and its law's per-point arrays (mpm/fields.hpp), freshly declared.
template <class G>
FieldList point_arrays(Body<G>& body) {
  FieldList list;
  body.declare_fields(list);
  if (body.law) body.law->declare_fields(body, list);
  return list;
}

/// Calls f(values, width) for every per-point array of `list` (doubles and bytes).
template <class F>
void for_point_arrays(const FieldList& list, F&& f) {
  for (const auto& field : list.fields()) {
    if (const auto* s = std::get_if<std::span<double>>(&field.data)) f(*s, field.width);
    if (const auto* u = std::get_if<std::span<std::uint8_t>>(&field.data)) f(*u, 1);
  }
}

/// Values per point over every per-point array.
inline int values_per_point(const FieldList& list) {
  int n = 0;
  for_point_arrays(list, [&](auto, int width) { n += width; });
  return n;
}

/// Pack the points whose dest[p] is not `me` into out[dest[p]] (all their arrays, as doubles),
/// move the others to the front in their order; returns how many stayed (the body is not resized).
template <class G>
std::int64_t pack_leaving(Body<G>& body, const std::vector<int>& dest, int me, std::vector<std::vector<double>>* out) {
  const FieldList list = point_arrays(body);
  std::int64_t kept = 0;
  for (std::int64_t p = 0; p < body.size(); ++p) {
    if (dest[p] != me) {
      if (out != nullptr)
        for_point_arrays(list, [&](auto values, int width) {
          for (int w = 0; w < width; ++w) (*out)[dest[p]].push_back(static_cast<double>(values[p * width + w]));
        });
      continue;
    }
    if (kept != p)
      for_point_arrays(list, [&](auto values, int width) {
        for (int w = 0; w < width; ++w) values[kept * width + w] = values[p * width + w];
      });
    ++kept;
  }
  return kept;
}
}  // namespace detail

/// Keep only the points of `body` inside this rank's block (a run's start: every rank built the
/// whole scene).
template <class G>
void keep_owned_points(Body<G>& body, const Decomposition<G::dim>& dec) {
  std::vector<int> dest(static_cast<std::size_t>(body.size()));
  for (std::int64_t p = 0; p < body.size(); ++p) dest[p] = dec.owner(body.x_m[p]);
  body.resize(detail::pack_leaving(body, dest, dec.rank(), nullptr));
}

/// Move the points of `body` whose position left this rank's block to their owners (one
/// all-to-all per body): every per-point array the body and its law declare (mpm/fields.hpp)
/// travels with the point. Points that stay keep their order; arrivals are appended in the
/// senders' rank order. Positions are wrapped on split periodic axes first (the global grid's
/// wrap, as G2P does on an unsplit one). Returns the number of points that left this rank.
template <class G>
std::int64_t migrate_points(Body<G>& body, const Decomposition<G::dim>& dec) {
  const int me = dec.rank();
  std::vector<int> dest(static_cast<std::size_t>(body.size()));
  std::int64_t leaving = 0;
  std::array<bool, G::dim> wrap{};
  bool any_wrap = false;
  for (int a = 0; a < G::dim; ++a) any_wrap |= wrap[a] = dec.split(a) && dec.global().periodic[a];
  for (std::int64_t p = 0; p < body.size(); ++p) {
    // A split periodic axis is not periodic in the local grid: G2P left the wrap to this pass.
    if (any_wrap)
      for (int a = 0; a < G::dim; ++a)
        if (wrap[a]) body.x_m[p][a] = dec.global().wrapped(a, body.x_m[p][a]);
    dest[p] = dec.owner(body.x_m[p]);
    leaving += dest[p] != me;
  }
  if (!comm::any(leaving > 0)) return 0;
  std::vector<std::vector<double>> out(static_cast<std::size_t>(dec.ranks()));
  const std::int64_t kept = detail::pack_leaving(body, dest, me, &out);
  const auto in = comm::alltoallv(out);
  const int per_point = detail::values_per_point(detail::point_arrays(body));
  std::int64_t arriving = 0;
  for (const auto& buf : in) arriving += static_cast<std::int64_t>(buf.size()) / per_point;
  body.resize(kept + arriving);
  const FieldList list = detail::point_arrays(body);  // (the arrays may have moved)
  std::int64_t p = kept;
  for (const auto& buf : in)
    for (std::size_t k = 0; k < buf.size(); ++p)
      detail::for_point_arrays(list, [&](auto values, int width) {
        using T = typename decltype(values)::value_type;
        for (int w = 0; w < width; ++w) values[p * width + w] = static_cast<T>(buf[k++]);
      });
  return leaving;
}

/// Every rank's points of `body` onto rank 0, appended after its own in rank order (to write a
/// frame or a checkpoint of the whole body). Returns the number of points the body had before:
/// Body::resize back to it afterwards (rank 0; the other ranks' bodies are unchanged).
template <class G>
std::int64_t gather_points_to_root(Body<G>& body) {
  const std::int64_t own = body.size();
  std::vector<double> packed;
  if (!comm::is_root()) {
    const FieldList list = detail::point_arrays(body);
    packed.reserve(static_cast<std::size_t>(own * detail::values_per_point(list)));
    for (std::int64_t p = 0; p < own; ++p)
      detail::for_point_arrays(list, [&](auto values, int width) {
        for (int w = 0; w < width; ++w) packed.push_back(static_cast<double>(values[p * width + w]));
      });
  }
  const std::vector<double> all = comm::gather_to_root(packed);
  if (!comm::is_root()) return own;
  const int per_point = detail::values_per_point(detail::point_arrays(body));
  body.resize(own + static_cast<std::int64_t>(all.size()) / per_point);
  const FieldList list = detail::point_arrays(body);
  std::size_t k = 0;
  for (std::int64_t p = own; p < body.size(); ++p)
    detail::for_point_arrays(list, [&](auto values, int width) {
      using T = typename decltype(values)::value_type;
      for (int w = 0; w < width; ++w) values[p * width + w] = static_cast<T>(all[k++]);
    });
  return own;
}

/// The global grid's physical nodes that this rank owns: the box of `extent` nodes per axis
/// from node `begin` (global logical indices; unused axes 0 and 1). Its first node is the local
/// grid's logical node 0; a block at a non-periodic upper end owns the last node layer too.
struct OwnedNodes {
  std::array<int, 3> begin{0, 0, 0}, extent{1, 1, 1};
};
template <int D>
OwnedNodes owned_physical_nodes(const Decomposition<D>& dec, const Grid<D>& local) {
  OwnedNodes box;
  for (int a = 0; a < D; ++a) {
    const bool last = dec.coords()[a] == dec.dims()[a] - 1;
    box.begin[a] = dec.block_begin(a);
    box.extent[a] = local.cells[a] + (last && !dec.global().periodic[a] ? 1 : 0);
  }
  return box;
}

/// f(local flat index, local logical (i, j, k)) for each node of owned_physical_nodes, x fastest.
template <int D, class F>
void for_owned_physical_nodes(const Decomposition<D>& dec, const Grid<D>& local, F&& f) {
  const OwnedNodes box = owned_physical_nodes(dec, local);
  for (int k = 0; k < box.extent[2]; ++k)
    for (int j = 0; j < box.extent[1]; ++j)
      for (int i = 0; i < box.extent[0]; ++i) {
        const std::array<int, 3> l{i, j, k};
        int flat = 0;
        for (int a = 0; a < D; ++a) flat += local.storage_index(a, l[a]) * local.stride(a);
        f(static_cast<std::size_t>(flat), l);
      }
}

/// A nodal array of the local grid on the global grid's physical nodes (x fastest), on rank 0
/// (empty elsewhere): each node from its owner.
template <int D>
std::vector<double> gather_physical_nodes(const Decomposition<D>& dec, const Grid<D>& local,
                                          std::span<const double> values) {
  const Grid<D>& g = dec.global();
  std::array<int, 3> nodes{1, 1, 1};
  for (int a = 0; a < D; ++a) nodes[a] = g.periodic[a] ? g.cells[a] : g.cells[a] + 1;
  std::vector<double> packed;  // (global flat index, value) pairs
  for_owned_physical_nodes(dec, local, [&](std::size_t flat, const std::array<int, 3>& l) {
    int global_flat = 0, scale = 1;
    for (int a = 0; a < D; ++a) {
      global_flat += (dec.block_begin(a) + l[a]) * scale;
      scale *= nodes[a];
    }
    packed.push_back(global_flat);
    packed.push_back(values[flat]);
  });
  const std::vector<double> all = comm::gather_to_root(packed);
  std::vector<double> out;
  if (!comm::is_root()) return out;
  out.assign(static_cast<std::size_t>(nodes[0]) * nodes[1] * nodes[2], 0.0);
  for (std::size_t q = 0; q + 1 < all.size(); q += 2) out[static_cast<std::size_t>(all[q])] = all[q + 1];
  return out;
}

}  // namespace oobleck::mpm
