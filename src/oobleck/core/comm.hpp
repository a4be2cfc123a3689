#pragma once
// The MPI layer (docs/mpi.md): the one place that calls MPI (parallel HDF5 also opens its
// files on MPI_COMM_WORLD, io/detail/h5.cpp). Every other file talks to the ranks through these
// functions, which are plain serial code in a build without MPI and in a process that was not
// started by mpirun (a one-rank world).
//
//   comm::init(argc, argv);          // main(): starts MPI only under mpirun (Open MPI's environment)
//   if (comm::size() > 1) ...        // a decomposed run
//   comm::sum(values);               // MPI_Allreduce, in place
//
// Threads: MPI is initialised with MPI_THREAD_FUNNELED; only the process's main thread (thread
// 0 of an OpenMP region) calls these functions.
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace oobleck::comm {

/// Start MPI when this process was started by mpirun (idempotent; a no-op otherwise or in a build
/// without MPI). Call before anything else in main().
void init(int& argc, char**& argv);
/// End MPI (after the last collective call; a no-op if init did not start it).
void finalize();
/// True when the binary was built with MPI.
bool built_with_mpi();
/// The environment says this process is one of an mpirun's ranks.
bool launched_by_mpirun();

int rank();
int size();
/// This process writes the run's files and prints its messages (rank 0).
inline bool is_root() { return rank() == 0; }

/// Allreduce sums in place (MPI_Allreduce: the order of the additions is the library's).
void sum(std::span<double> values);
/// Sums in place that are bit for bit the same on every rank: every rank's values gathered
/// (MPI_Allgather) and added in rank order on each. For the few numbers that feed state every
/// rank holds a copy of (a rigid body's velocity, a motor's correction); P × values.size() doubles.
void sum_ordered(std::span<double> values);
/// Element-wise minimum / maximum over the ranks, in place (exact).
void min(std::span<double> values);
void max(std::span<double> values);
void sum(std::span<std::int64_t> values);
double sum(double value);
std::int64_t sum(std::int64_t value);
double min(double value);
double max(double value);
std::int64_t min(std::int64_t value);
std::int64_t max(std::int64_t value);
/// Whether the flag is set on any rank.
bool any(bool flag);
/// Rank 0's string on every rank.
std::string broadcast(const std::string& from_root);
/// Every rank's values, concatenated in rank order, on rank 0 (empty elsewhere).
std::vector<double> gather_to_root(std::span<const double> values);
/// Every rank's values (the same count on each), concatenated in rank order, on every rank
/// (MPI_Allgather).
std::vector<std::int64_t> all_gather(std::span<const std::int64_t> values);

/// MPI_Sendrecv of doubles: `send` to rank `to`, `recv` (its size is the expected count) from rank
/// `from`; -1 for either means no partner on that side.
void sendrecv(std::span<const double> send, int to, std::span<double> recv, int from, int tag);
/// Every rank sends send[r] to rank r and gets what each rank sent it, in rank order.
std::vector<std::vector<double>> alltoallv(const std::vector<std::vector<double>>& send);
void barrier();
/// Stop every rank (MPI_Abort) with `code`; exit(code) without MPI.
[[noreturn]] void abort(int code);

/// Wall time [s] spent inside the functions above (the run's communication share).
double communication_seconds();

/// A Cartesian rank grid: MPI_Cart_create's layout (row-major: the last axis varies fastest).
int cart_rank(std::span<const int> dims, std::span<const int> coords);
std::vector<int> cart_coords(std::span<const int> dims, int rank);

}  // namespace oobleck::comm
