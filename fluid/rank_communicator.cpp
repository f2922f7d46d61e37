#include "fluid/rank_communicator.h"

#include <mpi.h>

#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

namespace meniscus::fluid {

namespace {

/// The private session directory of a plain run's MPI (ensure_mpi_initialized()), empty when
/// there is none.
std::string& session_directory() {
    static std::string directory;
    return directory;
}

void finalize_mpi_at_exit() {
    std::lock_guard<std::mutex> guard(mpi_lock());
    int finalized = 0;
    MPI_Finalized(&finalized);
    if (!finalized)
        MPI_Finalize();
    if (!session_directory().empty()) {
        std::error_code ignored;
        std::filesystem::remove_all(session_directory(), ignored);
    }
}

/// A new directory of its own for this process's MPI session files, under $TMPDIR (or /tmp);
/// empty when none can be made (Open MPI then uses its default).
std::string make_session_directory() {
    const char* tmp = std::getenv("TMPDIR");
    std::string pattern =
        std::string(tmp != nullptr && *tmp != '\0' ? tmp : "/tmp") + "/meniscus-mpi.XXXXXX";
    std::vector<char> path(pattern.begin(), pattern.end());
    path.push_back('\0');
    return mkdtemp(path.data()) != nullptr ? std::string(path.data()) : std::string();
}

void check_mpi(int error, const char* call) {
    if (error == MPI_SUCCESS)
        return;
    char text[MPI_MAX_ERROR_STRING] = {};
    int length = 0;
    MPI_Error_string(error, text, &length);
    throw std::runtime_error(std::string("MPI: ") + call + " failed: " + text);
}

int message_count(std::size_t count) {
    if (count > static_cast<std::size_t>(std::numeric_limits<int>::max()))
        throw std::runtime_error("RankCommunicator: a message of " + std::to_string(count) +
                                 " values exceeds MPI's int count");
    return static_cast<int>(count);
}

std::atomic<unsigned long long> g_exchanged_bytes{0};
std::atomic<unsigned long long> g_exchanges{0};
std::atomic<unsigned long long> g_reductions{0};

}  // namespace

CommunicationCounts communication_counts() {
    return {g_exchanged_bytes.load(), g_exchanges.load(), g_reductions.load()};
}

std::mutex& mpi_lock() {
    static std::mutex lock;
    return lock;
}

bool launched_by_mpi_launcher() {
    for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE"})
        if (std::getenv(name) != nullptr)
            return true;
    return false;
}

// MPI for a plain run (no mpirun), measured on Debian 12 with Open MPI 4.1.4, as root:
//
// - Open MPI refuses root only in its launcher (mpirun/orterun need --allow-run-as-root or
//   OMPI_ALLOW_RUN_AS_ROOT=1 + OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1). A process that calls
//   MPI_Init_thread without a launcher is a "singleton" and starts fine as root with no
//   variables set.
// - But by default the singleton forks a helper daemon (`orted --hnp`), in case it later calls
//   MPI_Comm_spawn: a second process per run, sockets, ~0.3 s, and where the parent is killed or
//   PID 1 does not reap (containers) a zombie orted is left behind (seen here). We never spawn, so
//   a singleton is made *isolated* (OMPI_MCA_ess_singleton_isolated=1): no daemon.
// - One process only talks to itself: the point-to-point layer is pinned to ob1 over the `self`
//   transport (OMPI_MCA_pml=ob1, OMPI_MCA_btl=self). Without this Open MPI probes UCX, openib,
//   libfabric and shared memory at every start (0.28 s → 0.04 s for MPI_Init_thread here) and
//   the shared-memory transport would create a segment file.
// - Open MPI installs handlers for SIGSEGV/SIGBUS/SIGFPE/SIGABRT that print its own backtrace;
//   OMPI_MCA_opal_signal="" keeps the program's (and the sanitizers') handling of those signals.
// - Every singleton keeps its session files under $TMPDIR/ompi.<host>.<uid>/jf.0/1, the same
//   path for all of them: one that ends removes the directory that one starting beside it is
//   creating, whose MPI_Init then fails ("A call to mkdir was unable to create the desired
//   directory ... jf.0/1", seen once in 738 tests run two at a time under load). Each plain run
//   gets a directory of its own (OMPI_MCA_orte_tmpdir_base, a mkdtemp under $TMPDIR), removed
//   after MPI_Finalize.
// All are set with setenv(..., overwrite = 0), so a user's own OMPI_MCA_* settings win, and only
// when no MPI launcher started the process (under mpirun the launcher's set-up is left alone).
// MPI_Finalize runs from std::atexit; handlers registered later (hypre's HYPRE_Finalize) run
// before it.
void ensure_mpi_initialized() {
    static std::once_flag once;
    std::call_once(once, [] {
        std::lock_guard<std::mutex> guard(mpi_lock());
        int initialized = 0;
        MPI_Initialized(&initialized);
        int finalized = 0;
        MPI_Finalized(&finalized);
        if (finalized)
            throw std::runtime_error("MPI has already been finalised");
        if (initialized)
            return;  // someone else's MPI: theirs to end
        if (!launched_by_mpi_launcher()) {
            setenv("OMPI_MCA_ess_singleton_isolated", "1", 0);
            setenv("OMPI_MCA_pml", "ob1", 0);
            setenv("OMPI_MCA_btl", "self", 0);
            setenv("OMPI_MCA_opal_signal", "", 0);
            if (std::getenv("OMPI_MCA_orte_tmpdir_base") == nullptr) {
                session_directory() = make_session_directory();
                if (!session_directory().empty())
                    setenv("OMPI_MCA_orte_tmpdir_base", session_directory().c_str(), 0);
            }
        }
        int provided = 0;
        if (MPI_Init_thread(nullptr, nullptr, MPI_THREAD_SERIALIZED, &provided) != MPI_SUCCESS)
            throw std::runtime_error("MPI_Init_thread failed");
        if (provided < MPI_THREAD_SERIALIZED)
            throw std::runtime_error("MPI does not provide MPI_THREAD_SERIALIZED");
        std::atexit(finalize_mpi_at_exit);
    });
}

RankCommunicator RankCommunicator::world() {
    ensure_mpi_initialized();
    std::lock_guard<std::mutex> guard(mpi_lock());
    int rank = 0, size = 1;
    check_mpi(MPI_Comm_rank(MPI_COMM_WORLD, &rank), "MPI_Comm_rank");
    check_mpi(MPI_Comm_size(MPI_COMM_WORLD, &size), "MPI_Comm_size");
    return RankCommunicator(true, rank, size);
}

double RankCommunicator::sum(double value) const {
    std::vector<double> v = {value};
    sum_in_place(v);
    return v[0];
}

double RankCommunicator::max(double value) const {
    if (!m_world)
        return value;
    double result = value;
    ++g_reductions;
    std::lock_guard<std::mutex> guard(mpi_lock());
    check_mpi(MPI_Allreduce(&value, &result, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD),
              "MPI_Allreduce");
    return result;
}

double RankCommunicator::min(double value) const {
    return -max(-value);
}

void RankCommunicator::sum_in_place(std::vector<double>& values) const {
    if (!m_world || values.empty())
        return;
    ++g_reductions;
    std::lock_guard<std::mutex> guard(mpi_lock());
    check_mpi(MPI_Allreduce(MPI_IN_PLACE, values.data(), message_count(values.size()), MPI_DOUBLE,
                            MPI_SUM, MPI_COMM_WORLD),
              "MPI_Allreduce");
}

bool RankCommunicator::all(bool value) const {
    return min(value ? 1.0 : 0.0) > 0.5;
}

std::vector<std::vector<double>> RankCommunicator::exchange(
    const std::vector<std::vector<double>>& sends) const {
    if (sends.size() != static_cast<std::size_t>(m_size))
        throw std::invalid_argument("RankCommunicator::exchange: " + std::to_string(sends.size()) +
                                    " messages for " + std::to_string(m_size) + " ranks");
    if (!m_world)
        return sends;
    std::vector<int> send_counts(static_cast<std::size_t>(m_size)), send_offsets(send_counts);
    std::vector<double> send_buffer;
    for (std::size_t r = 0; r < sends.size(); ++r) {
        send_offsets[r] = message_count(send_buffer.size());
        send_counts[r] = message_count(sends[r].size());
        send_buffer.insert(send_buffer.end(), sends[r].begin(), sends[r].end());
        if (static_cast<int>(r) != m_rank)
            g_exchanged_bytes += sizeof(double) * sends[r].size();
    }
    ++g_exchanges;
    std::vector<int> receive_counts(send_counts.size()), receive_offsets(send_counts.size());
    std::vector<double> receive_buffer;
    {
        std::lock_guard<std::mutex> guard(mpi_lock());
        check_mpi(MPI_Alltoall(send_counts.data(), 1, MPI_INT, receive_counts.data(), 1, MPI_INT,
                               MPI_COMM_WORLD),
                  "MPI_Alltoall");
        std::size_t total = 0;
        for (std::size_t r = 0; r < receive_counts.size(); ++r) {
            receive_offsets[r] = message_count(total);
            total += static_cast<std::size_t>(receive_counts[r]);
        }
        receive_buffer.resize(total);
        check_mpi(MPI_Alltoallv(send_buffer.data(), send_counts.data(), send_offsets.data(),
                                MPI_DOUBLE, receive_buffer.data(), receive_counts.data(),
                                receive_offsets.data(), MPI_DOUBLE, MPI_COMM_WORLD),
                  "MPI_Alltoallv");
    }
    std::vector<std::vector<double>> received(static_cast<std::size_t>(m_size));
    for (std::size_t r = 0; r < received.size(); ++r)
        received[r].assign(receive_buffer.begin() + receive_offsets[r],
                           receive_buffer.begin() + receive_offsets[r] + receive_counts[r]);
    return received;
}

std::vector<double> RankCommunicator::broadcast(std::vector<double> values, int root) const {
    if (!m_world)
        return values;
    std::lock_guard<std::mutex> guard(mpi_lock());
    unsigned long long count = values.size();
    check_mpi(MPI_Bcast(&count, 1, MPI_UNSIGNED_LONG_LONG, root, MPI_COMM_WORLD), "MPI_Bcast");
    values.resize(static_cast<std::size_t>(count));
    check_mpi(
        MPI_Bcast(values.data(), message_count(values.size()), MPI_DOUBLE, root, MPI_COMM_WORLD),
        "MPI_Bcast");
    return values;
}

void RankCommunicator::barrier() const {
    if (!m_world)
        return;
    std::lock_guard<std::mutex> guard(mpi_lock());
    check_mpi(MPI_Barrier(MPI_COMM_WORLD), "MPI_Barrier");
}

void RankCommunicator::abort(int code) const {
    if (!m_world)
        return;
    // No lock: another thread may hold it inside a collective call that will never return.
    MPI_Abort(MPI_COMM_WORLD, code);
}

}  // namespace meniscus::fluid
