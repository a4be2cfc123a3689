#include "oobleck/core/comm.hpp"

#include <algorithm>
#include <chrono>
#include <type_traits>
#include <cstdlib>
#include <cstring>

#ifdef OOBLECK_HAVE_MPI
// The C interface only (Open MPI's and MPICH's mpi.h otherwise pull in the deprecated C++
// bindings, which need libmpi_cxx).
#define OMPI_SKIP_MPICXX 1
#define MPICH_SKIP_MPICXX 1
#include <mpi.h>
#endif

namespace oobleck::comm {

namespace {

double g_comm_seconds = 0.0;

double now() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

/// Adds the wall time of its scope to g_comm_seconds.
struct Timed {
  double t0 = now();
  ~Timed() { g_comm_seconds += now() - t0; }
  Timed() = default;
  Timed(const Timed&) = delete;
  Timed& operator=(const Timed&) = delete;
};

#ifdef OOBLECK_HAVE_MPI
bool g_started = false;
bool active() { return g_started; }
#endif

}  // namespace

bool built_with_mpi() {
#ifdef OOBLECK_HAVE_MPI
  return true;
#else
  return false;
#endif
}

bool launched_by_mpirun() {
  // Open MPI (OMPI_COMM_WORLD_SIZE), PMIx launchers (PMIX_RANK), MPICH's Hydra (PMI_SIZE).
  const char* const vars[] = {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_SIZE"};
  return std::ranges::any_of(vars, [](const char* v) { return std::getenv(v) != nullptr; });
}

void init([[maybe_unused]] int& argc, [[maybe_unused]] char**& argv) {
#ifdef OOBLECK_HAVE_MPI
  if (g_started || !launched_by_mpirun()) return;
  int provided = 0;
  MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
  MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_ARE_FATAL);
  g_started = true;
#endif
}

void finalize() {
#ifdef OOBLECK_HAVE_MPI
  if (!g_started) return;
  int done = 0;
  MPI_Finalized(&done);
  if (!done) MPI_Finalize();
  g_started = false;
#endif
}

int rank() {
#ifdef OOBLECK_HAVE_MPI
  if (active()) {
    int r = 0;
    MPI_Comm_rank(MPI_COMM_WORLD, &r);
    return r;
  }
#endif
  return 0;
}

int size() {
#ifdef OOBLECK_HAVE_MPI
  if (active()) {
    int n = 1;
    MPI_Comm_size(MPI_COMM_WORLD, &n);
    return n;
  }
#endif
  return 1;
}

void sum([[maybe_unused]] std::span<double> values) {
#ifdef OOBLECK_HAVE_MPI
  if (!active() || values.empty()) return;
  Timed t;
  MPI_Allreduce(MPI_IN_PLACE, values.data(), static_cast<int>(values.size()), MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
#endif
}

void sum([[maybe_unused]] std::span<std::int64_t> values) {
#ifdef OOBLECK_HAVE_MPI
  if (!active() || values.empty()) return;
  Timed t;
  MPI_Allreduce(MPI_IN_PLACE, values.data(), static_cast<int>(values.size()), MPI_INT64_T, MPI_SUM, MPI_COMM_WORLD);
#endif
}

void sum_ordered([[maybe_unused]] std::span<double> values) {
#ifdef OOBLECK_HAVE_MPI
  if (!active() || values.empty()) return;
  Timed t;
  const int n = static_cast<int>(values.size());
  std::vector<double> all(values.size() * static_cast<std::size_t>(size()));
  MPI_Allgather(values.data(), n, MPI_DOUBLE, all.data(), n, MPI_DOUBLE, MPI_COMM_WORLD);
  std::fill(values.begin(), values.end(), 0.0);
  for (std::size_t r = 0; r < all.size(); r += values.size())
    for (std::size_t k = 0; k < values.size(); ++k) values[k] += all[r + k];
#endif
}

namespace {
void reduce_extreme([[maybe_unused]] std::span<double> values, [[maybe_unused]] bool minimum) {
#ifdef OOBLECK_HAVE_MPI
  if (!active() || values.empty()) return;
  Timed t;
  MPI_Allreduce(MPI_IN_PLACE, values.data(), static_cast<int>(values.size()), MPI_DOUBLE, minimum ? MPI_MIN : MPI_MAX,
                MPI_COMM_WORLD);
#endif
}
}  // namespace

void min(std::span<double> values) { reduce_extreme(values, true); }
void max(std::span<double> values) { reduce_extreme(values, false); }

double sum(double value) {
  sum(std::span<double>(&value, 1));
  return value;
}
std::int64_t sum(std::int64_t value) {
  sum(std::span<std::int64_t>(&value, 1));
  return value;
}

namespace {
template <class T>
T reduce_one(T value, [[maybe_unused]] bool minimum) {
#ifdef OOBLECK_HAVE_MPI
  if (!active()) return value;
  Timed t;
  const MPI_Datatype type = std::is_same_v<T, double> ? MPI_DOUBLE : MPI_INT64_T;
  MPI_Allreduce(MPI_IN_PLACE, &value, 1, type, minimum ? MPI_MIN : MPI_MAX, MPI_COMM_WORLD);
#endif
  return value;
}
}  // namespace

double min(double value) { return reduce_one(value, true); }
double max(double value) { return reduce_one(value, false); }
std::int64_t min(std::int64_t value) { return reduce_one(value, true); }
std::int64_t max(std::int64_t value) { return reduce_one(value, false); }
bool any(bool flag) { return max(static_cast<std::int64_t>(flag)) != 0; }

std::string broadcast(const std::string& from_root) {
#ifdef OOBLECK_HAVE_MPI
  if (!active()) return from_root;
  Timed t;
  auto n = static_cast<std::int64_t>(from_root.size());
  MPI_Bcast(&n, 1, MPI_INT64_T, 0, MPI_COMM_WORLD);
  std::string s = is_root() ? from_root : std::string(static_cast<std::size_t>(n), '\0');
  MPI_Bcast(s.data(), static_cast<int>(n), MPI_CHAR, 0, MPI_COMM_WORLD);
  return s;
#else
  return from_root;
#endif
}

std::vector<double> gather_to_root(std::span<const double> values) {
#ifdef OOBLECK_HAVE_MPI
  if (active()) {
    Timed t;
    const int n = size();
    int mine = static_cast<int>(values.size());
    std::vector<int> counts(static_cast<std::size_t>(n)), offsets(static_cast<std::size_t>(n));
    MPI_Gather(&mine, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
    std::vector<double> all;
    if (is_root()) {
      int total = 0;
      for (int r = 0; r < n; ++r) {
        offsets[r] = total;
        total += counts[r];
      }
      all.resize(static_cast<std::size_t>(total));
    }
    MPI_Gatherv(values.data(), mine, MPI_DOUBLE, all.data(), counts.data(), offsets.data(), MPI_DOUBLE, 0,
                MPI_COMM_WORLD);
    return all;
  }
#endif
  return {values.begin(), values.end()};
}

std::vector<std::int64_t> all_gather(std::span<const std::int64_t> values) {
#ifdef OOBLECK_HAVE_MPI
  if (active()) {
    Timed t;
    std::vector<std::int64_t> all(values.size() * static_cast<std::size_t>(size()));
    MPI_Allgather(values.data(), static_cast<int>(values.size()), MPI_INT64_T, all.data(),
                  static_cast<int>(values.size()), MPI_INT64_T, MPI_COMM_WORLD);
    return all;
  }
#endif
  return {values.begin(), values.end()};
}

void sendrecv(std::span<const double> send, int to, std::span<double> recv, int from, [[maybe_unused]] int tag) {
#ifdef OOBLECK_HAVE_MPI
  if (active()) {
    Timed t;
    MPI_Sendrecv(send.data(), to >= 0 ? static_cast<int>(send.size()) : 0, MPI_DOUBLE, to >= 0 ? to : MPI_PROC_NULL,
                 tag, recv.data(), from >= 0 ? static_cast<int>(recv.size()) : 0, MPI_DOUBLE,
                 from >= 0 ? from : MPI_PROC_NULL, tag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    return;
  }
#endif
  // One rank: only a message to itself.
  if (to == 0 && from == 0 && send.size() == recv.size()) std::memcpy(recv.data(), send.data(), send.size_bytes());
}

std::vector<std::vector<double>> alltoallv(const std::vector<std::vector<double>>& send) {
#ifdef OOBLECK_HAVE_MPI
  if (active()) {
    Timed t;
    const int n = size();
    std::vector<int> scount(n), sdispl(n), rcount(n), rdispl(n);
    std::vector<double> sbuf;
    for (int r = 0; r < n; ++r) {
      scount[r] = static_cast<int>(send[r].size());
      sdispl[r] = static_cast<int>(sbuf.size());
      sbuf.insert(sbuf.end(), send[r].begin(), send[r].end());
    }
    MPI_Alltoall(scount.data(), 1, MPI_INT, rcount.data(), 1, MPI_INT, MPI_COMM_WORLD);
    int total = 0;
    for (int r = 0; r < n; ++r) {
      rdispl[r] = total;
      total += rcount[r];
    }
    std::vector<double> rbuf(static_cast<std::size_t>(total));
    MPI_Alltoallv(sbuf.data(), scount.data(), sdispl.data(), MPI_DOUBLE, rbuf.data(), rcount.data(), rdispl.data(),
                  MPI_DOUBLE, MPI_COMM_WORLD);
    std::vector<std::vector<double>> recv(static_cast<std::size_t>(n));
    for (int r = 0; r < n; ++r) recv[r].assign(rbuf.begin() + rdispl[r], rbuf.begin() + rdispl[r] + rcount[r]);
    return recv;
  }
#endif
  return send;
}

void barrier() {
#ifdef OOBLECK_HAVE_MPI
  if (active()) {
    Timed t;
    MPI_Barrier(MPI_COMM_WORLD);
  }
#endif
}

void abort(int code) {
#ifdef OOBLECK_HAVE_MPI
  if (active()) MPI_Abort(MPI_COMM_WORLD, code);
#endif
  std::exit(code);
}

double communication_seconds() { return g_comm_seconds; }

int cart_rank(std::span<const int> dims, std::span<const int> coords) {
  int r = 0;
  for (std::size_t a = 0; a < dims.size(); ++a) r = r * dims[a] + coords[a];
  return r;
}

std::vector<int> cart_coords(std::span<const int> dims, int rank) {
  std::vector<int> c(dims.size());
  for (std::size_t a = dims.size(); a-- > 0;) {
    c[a] = rank % dims[a];
    rank /= dims[a];
  }
  return c;
}

}  // namespace oobleck::comm
