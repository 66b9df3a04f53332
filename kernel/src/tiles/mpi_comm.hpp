// The few MPI calls a tiled run makes, behind plain functions so that no MPI
// header reaches the rest of the kernel. Built over Open MPI when CMake finds
// it (OROGEN_HAVE_MPI); without it, a process started by mpirun is refused
// with a message saying so, and a plain start works as always.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace orogen::mpi {

/// The number of processes mpirun started this run with (OMPI_COMM_WORLD_SIZE,
/// PMI_SIZE or PMIX_SIZE in the environment), or 0 when it was not started by mpirun.
int launched_size();

/// Whether this orogen was built with MPI.
bool built_with_mpi();

/// MPI for the life of the object: MPI_Init in the constructor, MPI_Finalize in the
/// destructor. Only made when launched_size() > 0. Throws orogen::Error if this
/// orogen was built without MPI.
class Session {
public:
    Session(int& argc, char**& argv);
    ~Session();
    Session(const Session&) = delete;
    Session& operator=(const Session&) = delete;
    int rank() const { return rank_; }
    int size() const { return size_; }

private:
    int rank_ = 0, size_ = 1;
};

// Collectives and point-to-point calls on MPI_COMM_WORLD (valid while a Session lives).

/// Element by element, the largest of every rank's `values[0..count)` (in place).
void max_all(int* values, int count);
/// Every rank's `send[0..count)` concatenated in rank order into `recv` (count × ranks values), on every rank.
void allgather(const int* send, int count, int* recv);
/// Every rank's `bytes` (any size, each below 2 GiB), in rank order, on every rank.
std::vector<std::string> allgather(std::string_view bytes);
/// `to_rank[r]` (one per rank) to rank r; returns what each rank sent this one, in rank order. The sizes
/// go first (one all-to-all), then only the non-empty messages, all posted at once, with `tag`.
std::vector<std::string> alltoall(std::span<const std::string> to_rank, int tag);
/// Send `send` to rank `to` and receive `recv` from rank `from` at once; -1 for
/// either means no such neighbour (nothing sent or received). The two sizes
/// may differ; `from` must send exactly `recv_bytes` with the same tag.
void sendrecv(const void* send, std::size_t send_bytes, int to, void* recv, std::size_t recv_bytes, int from, int tag);
void send(const void* data, std::size_t bytes, int to, int tag);
void recv(void* data, std::size_t bytes, int from, int tag);
/// `text` of rank 0 on every rank.
void broadcast(std::string& text);
/// Ends every rank at once (for a failure inside a collective that cannot be agreed on).
[[noreturn]] void abort_all(int exit_code);

}  // namespace orogen::mpi
