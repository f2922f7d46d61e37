#pragma once
/// \file The ranks of a distributed run (issue 40): the processes `mpirun -n K` started, or this
/// process alone. MPI (Debian libopenmpi-dev) is private to meniscus::fluid: no header of the
/// project includes <mpi.h>.
///
/// Every call into MPI (and into hypre, which calls MPI) holds mpi_lock(); MPI is initialised with
/// MPI_THREAD_SERIALIZED to match, so any thread may call, one at a time.

#include <mutex>
#include <vector>

namespace meniscus::fluid {

/// Initialises MPI once per process (thread-safe) if nobody has: under an MPI launcher as one
/// rank of the job, without one as a *singleton* set up for a plain run as root (see
/// rank_communicator.cpp for what and why); registers MPI_Finalize with std::atexit. An MPI that
/// someone else initialised is left to them. Throws std::runtime_error if MPI was already
/// finalised or MPI_Init_thread fails.
void ensure_mpi_initialized();

/// True when an MPI launcher (mpirun, srun, …) started this process: Open MPI's
/// OMPI_COMM_WORLD_SIZE, PMIx's PMIX_RANK or PMI's PMI_RANK / PMI_SIZE is set. Needs no MPI.
bool launched_by_mpi_launcher();

/// The lock every call into MPI or hypre holds (see the file comment).
std::mutex& mpi_lock();

/// What this process has sent to other ranks since it started (all RankCommunicator calls):
/// personalised exchanges (halos, gathers) and reductions, for the benchmarks' bytes per step.
struct CommunicationCounts {
    unsigned long long exchanged_bytes = 0;  ///< sent by exchange() to other ranks
    unsigned long long exchanges = 0;        ///< exchange() calls
    unsigned long long reductions = 0;       ///< sum/max/min/all/broadcast calls
};
CommunicationCounts communication_counts();

/// A group of ranks: all of MPI_COMM_WORLD, or this process alone (which makes no MPI call).
/// Collective calls must be made by every rank in the same order.
class RankCommunicator {
public:
    /// This process alone: rank 0 of 1; every collective is a local copy.
    static RankCommunicator self() { return RankCommunicator(false, 0, 1); }
    /// Every rank of MPI_COMM_WORLD (initialises MPI if needed).
    static RankCommunicator world();

    int rank() const { return m_rank; }
    int size() const { return m_size; }
    /// True for world() (even with one rank): hypre then runs on MPI_COMM_WORLD.
    bool is_world() const { return m_world; }

    /// Σ over the ranks of `value`, on every rank (MPI_Allreduce; deterministic for a given
    /// number of ranks).
    double sum(double value) const;
    /// max over the ranks, on every rank.
    double max(double value) const;
    /// min over the ranks, on every rank.
    double min(double value) const;
    /// Element-wise Σ over the ranks of `values` (the same length on every rank), in place.
    void sum_in_place(std::vector<double>& values) const;
    /// True on every rank iff `value` is true on every rank.
    bool all(bool value) const;
    /// Personalised all-to-all (MPI_Alltoallv): `sends[r]` goes to rank r (sends.size() == size());
    /// returns what each rank sent to this one, indexed by rank.
    std::vector<std::vector<double>> exchange(const std::vector<std::vector<double>>& sends) const;
    /// `value` of rank `root`, on every rank (MPI_Bcast).
    std::vector<double> broadcast(std::vector<double> values, int root) const;
    /// Waits for every rank.
    void barrier() const;
    /// Ends every rank of the job with `code` (MPI_Abort): what a rank that cannot go on must do,
    /// or the others wait in their next collective call for ever. One process: does nothing.
    void abort(int code) const;

private:
    RankCommunicator(bool world, int rank, int size) : m_world(world), m_rank(rank), m_size(size) {}
    bool m_world = false;
    int m_rank = 0;
    int m_size = 1;
};

}  // namespace meniscus::fluid
