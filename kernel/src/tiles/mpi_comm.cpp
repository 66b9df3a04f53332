#include "mpi_comm.hpp"

#include <orogen/error.hpp>

#include <algorithm>
#include <climits>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#ifdef OROGEN_HAVE_MPI
// The C API only: Open MPI's deprecated C++ bindings would need libmpi_cxx.
#define OMPI_SKIP_MPICXX 1
#define MPICH_SKIP_MPICXX 1
#include <mpi.h>
#endif

namespace orogen::mpi {

int launched_size() {
    for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE"})
        if (const char* v = std::getenv(name); v && *v) {
            const int n = std::atoi(v);
            if (n > 0) return n;
        }
    return 0;
}

#ifdef OROGEN_HAVE_MPI

bool built_with_mpi() { return true; }

namespace {
// MPI counts are ints: large messages go in pieces of at most 1 GiB.
constexpr std::size_t kPiece = std::size_t(1) << 30;

void check(int rc, const char* what) {
    if (rc == MPI_SUCCESS) return;
    char text[MPI_MAX_ERROR_STRING];
    int len = 0;
    MPI_Error_string(rc, text, &len);
    throw Error(std::string("MPI ") + what + " failed: " + std::string(text, std::size_t(len)));
}

// Posts `bytes` at `data` to (sending) or from `peer` as non-blocking pieces of at most kPiece, appended to
// `requests`; an empty message is one empty piece, as the peer posts one empty receive.
void post_pieces(std::vector<MPI_Request>& requests, char* data, std::size_t bytes, int peer, bool sending, int tag) {
    std::size_t done = 0;
    do {
        const std::size_t n = std::min(kPiece, bytes - done);
        requests.emplace_back();
        if (sending)
            check(MPI_Isend(data + done, int(n), MPI_BYTE, peer, tag, MPI_COMM_WORLD, &requests.back()), "MPI_Isend");
        else check(MPI_Irecv(data + done, int(n), MPI_BYTE, peer, tag, MPI_COMM_WORLD, &requests.back()), "MPI_Irecv");
        done += n;
    } while (done < bytes);
}
}  // namespace

Session::Session(int& argc, char**& argv) {
    int provided = 0;
    check(MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided), "MPI_Init");
    // Errors come back as codes and become orogen::Error (not MPI's default abort).
    MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
}

Session::~Session() { MPI_Finalize(); }

void max_all(int* values, int count) {
    check(MPI_Allreduce(MPI_IN_PLACE, values, count, MPI_INT, MPI_MAX, MPI_COMM_WORLD), "MPI_Allreduce");
}

void allgather(const int* send, int count, int* recv) {
    check(MPI_Allgather(send, count, MPI_INT, recv, count, MPI_INT, MPI_COMM_WORLD), "MPI_Allgather");
}

std::vector<std::string> allgather(std::string_view bytes) {
    int size = 1;
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    if (bytes.size() > std::size_t(INT_MAX)) throw Error("internal error: an allgather of 2 GiB or more");
    const int mine = int(bytes.size());
    std::vector<int> counts(static_cast<std::size_t>(size)), displs(static_cast<std::size_t>(size));
    check(MPI_Allgather(&mine, 1, MPI_INT, counts.data(), 1, MPI_INT, MPI_COMM_WORLD), "MPI_Allgather");
    std::int64_t total = 0;
    for (int r = 0; r < size; ++r) {
        displs[std::size_t(r)] = int(total);
        total += counts[std::size_t(r)];
    }
    if (total > INT_MAX) throw Error("internal error: an allgather of 2 GiB or more");
    std::string all(std::size_t(total), '\0');
    check(MPI_Allgatherv(bytes.data(), mine, MPI_BYTE, all.data(), counts.data(), displs.data(), MPI_BYTE,
                         MPI_COMM_WORLD),
          "MPI_Allgatherv");
    std::vector<std::string> parts;
    for (int r = 0; r < size; ++r)
        parts.push_back(all.substr(std::size_t(displs[std::size_t(r)]), std::size_t(counts[std::size_t(r)])));
    return parts;
}

std::vector<std::string> alltoall(std::span<const std::string> to_rank, int tag) {
    int size = 1, rank = 0;
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    if (to_rank.size() != std::size_t(size)) throw Error("internal error: alltoall needs one message per rank");
    const auto n = static_cast<std::size_t>(size);
    std::vector<unsigned long long> sizes_out(n), sizes_in(n);
    for (int r = 0; r < size; ++r) sizes_out[std::size_t(r)] = to_rank[std::size_t(r)].size();
    check(MPI_Alltoall(sizes_out.data(), 1, MPI_UNSIGNED_LONG_LONG, sizes_in.data(), 1, MPI_UNSIGNED_LONG_LONG,
                       MPI_COMM_WORLD),
          "MPI_Alltoall");
    std::vector<std::string> from_rank(n);
    std::vector<MPI_Request> requests;
    for (int r = 0; r < size; ++r) {
        const std::size_t k = std::size_t(r);
        if (r == rank) {
            from_rank[k] = to_rank[k];
            continue;
        }
        if (sizes_in[k] == 0) continue;
        from_rank[k].resize(std::size_t(sizes_in[k]));
        post_pieces(requests, from_rank[k].data(), from_rank[k].size(), r, false, tag);
    }
    for (int r = 0; r < size; ++r) {
        const std::size_t k = std::size_t(r);
        if (r != rank && sizes_out[k] != 0)
            post_pieces(requests, const_cast<char*>(to_rank[k].data()), to_rank[k].size(), r, true, tag);
    }
    if (!requests.empty())
        check(MPI_Waitall(int(requests.size()), requests.data(), MPI_STATUSES_IGNORE), "MPI_Waitall");
    return from_rank;
}

void sendrecv(const void* send_data, std::size_t send_bytes, int to, void* recv_data, std::size_t recv_bytes, int from,
              int tag) {
    // Non-blocking pieces, all posted, then waited for: the message to `to` and the one from `from` may
    // differ in size (export:tiles' fetch), and MPI matches the pieces of one sender and tag in order.
    std::vector<MPI_Request> requests;
    if (from >= 0) post_pieces(requests, static_cast<char*>(recv_data), recv_bytes, from, false, tag);
    if (to >= 0)
        post_pieces(requests, const_cast<char*>(static_cast<const char*>(send_data)), send_bytes, to, true, tag);
    if (!requests.empty())
        check(MPI_Waitall(int(requests.size()), requests.data(), MPI_STATUSES_IGNORE), "MPI_Waitall");
}

void send(const void* data, std::size_t bytes, int to, int tag) {
    std::size_t done = 0;
    do {
        const std::size_t n = std::min(kPiece, bytes - done);
        check(MPI_Send(static_cast<const char*>(data) + done, int(n), MPI_BYTE, to, tag, MPI_COMM_WORLD), "MPI_Send");
        done += n;
    } while (done < bytes);
}

void recv(void* data, std::size_t bytes, int from, int tag) {
    std::size_t done = 0;
    do {
        const std::size_t n = std::min(kPiece, bytes - done);
        check(MPI_Recv(static_cast<char*>(data) + done, int(n), MPI_BYTE, from, tag, MPI_COMM_WORLD, MPI_STATUS_IGNORE),
              "MPI_Recv");
        done += n;
    } while (done < bytes);
}

void broadcast(std::string& text) {
    unsigned long long n = text.size();
    check(MPI_Bcast(&n, 1, MPI_UNSIGNED_LONG_LONG, 0, MPI_COMM_WORLD), "MPI_Bcast");
    text.resize(std::size_t(n));
    if (n) check(MPI_Bcast(text.data(), int(n), MPI_CHAR, 0, MPI_COMM_WORLD), "MPI_Bcast");
}

void abort_all(int exit_code) {
    MPI_Abort(MPI_COMM_WORLD, exit_code);
    std::_Exit(exit_code);
}

#else  // built without MPI

bool built_with_mpi() { return false; }

namespace {
[[noreturn]] void unavailable() { throw Error("this orogen was built without MPI"); }
}  // namespace

Session::Session(int&, char**&) {
    throw Error(
        "started by mpirun, but this orogen was built without MPI: install Open MPI "
        "(apt-get install openmpi-bin libopenmpi-dev), configure again and rebuild, or run without mpirun");
}
Session::~Session() = default;
void max_all(int*, int) {}
void allgather(const int* send, int count, int* recv) { std::copy(send, send + count, recv); }
std::vector<std::string> allgather(std::string_view bytes) { return {std::string(bytes)}; }
std::vector<std::string> alltoall(std::span<const std::string> to_rank, int) {
    return {to_rank.empty() ? std::string() : to_rank.front()};
}
void sendrecv(const void*, std::size_t, int to, void*, std::size_t, int from, int) {
    if (to >= 0 || from >= 0) unavailable();
}
void send(const void*, std::size_t, int, int) { unavailable(); }
void recv(void*, std::size_t, int, int) { unavailable(); }
void broadcast(std::string&) {}
void abort_all(int exit_code) { std::_Exit(exit_code); }

#endif

}  // namespace orogen::mpi
