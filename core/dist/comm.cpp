// MPI behind comm.h. Built with MPI (TETSTREAM_MPI) or without: then world() says so, and the
// program packs on one process as before.
#include "dist/comm.h"

#include <cstdlib>
#include <cstring>
#include <limits>

#if TETSTREAM_MPI
#include <mpi.h>
#endif

namespace tetstream::dist {

bool launchedByMpi() {
  // Open MPI's mpirun, MPICH and Intel's mpiexec (PMI), PMIx launchers (srun --mpi=pmix, prterun).
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK", "MPI_LOCALNRANKS"})
    if (std::getenv(name)) return true;
  return false;
}

bool Reader::take(void* to, size_t n) {
  if (!ok_ || n > in_.size() - at_) {
    ok_ = false;
    std::memset(to, 0, n);
    return false;
  }
  if (n) std::memcpy(to, in_.data() + at_, n);
  at_ += n;
  return true;
}

#if TETSTREAM_MPI

namespace {

// MPI counts are ints: larger messages go in pieces of this many bytes.
constexpr uint64_t kPiece = uint64_t(1) << 30;

void sendPieces(int to, int tag, const uint8_t* data, uint64_t size) {
  for (uint64_t at = 0; at < size; at += kPiece)
    MPI_Send(data + at, int(std::min(kPiece, size - at)), MPI_BYTE, to, tag, MPI_COMM_WORLD);
}
void receivePieces(int from, int tag, uint8_t* data, uint64_t size) {
  for (uint64_t at = 0; at < size; at += kPiece)
    MPI_Recv(data + at, int(std::min(kPiece, size - at)), MPI_BYTE, from, tag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
}

template <typename T>
void reduce(std::vector<T>& v, MPI_Datatype type, MPI_Op op) {
  if (!v.empty()) MPI_Allreduce(MPI_IN_PLACE, v.data(), int(v.size()), type, op, MPI_COMM_WORLD);
}

}  // namespace

bool mpiAvailable() { return true; }

Result Comm::world(std::unique_ptr<Comm>& out) {
  int ready = 0;
  MPI_Initialized(&ready);
  if (!ready) {
    int provided = 0;
    // Only the main thread calls MPI; the packer's own threads never do.
    MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
  }
  out.reset(new Comm());
  MPI_Comm_rank(MPI_COMM_WORLD, &out->rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &out->size_);
  return Result::success();
}

Comm::~Comm() {
  int done = 0;
  MPI_Finalized(&done);
  if (!done) MPI_Finalize();
}

void Comm::send(int to, int tag, const Bytes& data, bool failed) {
  uint64_t head[2] = {failed ? 1u : 0u, failed ? 0 : data.size()};
  MPI_Send(head, 2, MPI_UINT64_T, to, tag, MPI_COMM_WORLD);
  if (!failed) sendPieces(to, tag, data.data(), data.size());
}

bool Comm::receive(int from, int tag, Bytes& data) {
  uint64_t head[2] = {0, 0};
  MPI_Recv(head, 2, MPI_UINT64_T, from, tag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  data.assign(head[1], 0);
  receivePieces(from, tag, data.data(), head[1]);
  return head[0] == 0;
}

std::vector<Bytes> Comm::allGather(const Bytes& mine) {
  std::vector<uint64_t> sizes(static_cast<size_t>(size_), 0);
  sizes[size_t(rank_)] = mine.size();
  sumInPlace(sizes);
  std::vector<Bytes> all(static_cast<size_t>(size_));
  uint64_t total = 0;
  for (uint64_t n : sizes) total += n;
  if (total <= uint64_t(std::numeric_limits<int>::max())) {
    // One collective for all ranks (the library picks a ring or a tree for hundreds of them);
    // its counts and displacements are ints, hence the bound.
    std::vector<int> counts(sizes.size()), starts(sizes.size());
    for (size_t r = 0, at = 0; r < sizes.size(); at += sizes[r], ++r) {
      counts[r] = int(sizes[r]);
      starts[r] = int(at);
    }
    Bytes flat(total);
    MPI_Allgatherv(mine.data(), int(mine.size()), MPI_BYTE, flat.data(), counts.data(), starts.data(), MPI_BYTE,
                   MPI_COMM_WORLD);
    for (size_t r = 0; r < sizes.size(); ++r)
      all[r].assign(flat.begin() + starts[r], flat.begin() + starts[r] + counts[r]);
    return all;
  }
  for (int r = 0; r < size_; ++r) {  // more than 2 GB in all: one broadcast per rank, in pieces
    Bytes& b = all[size_t(r)];
    b = r == rank_ ? mine : Bytes(sizes[size_t(r)]);
    for (uint64_t at = 0; at < b.size(); at += kPiece)
      MPI_Bcast(b.data() + at, int(std::min(kPiece, b.size() - at)), MPI_BYTE, r, MPI_COMM_WORLD);
  }
  return all;
}

std::vector<Bytes> Comm::allToAll(const std::vector<Bytes>& sendTo) {
  const size_t n = size_t(size_);
  std::vector<uint64_t> sizes(n), incoming(n);
  for (size_t r = 0; r < n; ++r) sizes[r] = sendTo[r].size();
  MPI_Alltoall(sizes.data(), 1, MPI_UINT64_T, incoming.data(), 1, MPI_UINT64_T, MPI_COMM_WORLD);
  std::vector<Bytes> got(n);
  std::vector<MPI_Request> requests;
  constexpr int kTag = 1 << 20;  // (above the tags the packer's own messages use)
  for (size_t r = 0; r < n; ++r) {
    got[r].resize(incoming[r]);
    for (uint64_t at = 0; at < incoming[r]; at += kPiece)
      MPI_Irecv(got[r].data() + at, int(std::min(kPiece, incoming[r] - at)), MPI_BYTE, int(r), kTag, MPI_COMM_WORLD,
                &requests.emplace_back());
  }
  for (size_t r = 0; r < n; ++r)
    for (uint64_t at = 0; at < sizes[r]; at += kPiece)
      MPI_Isend(sendTo[r].data() + at, int(std::min(kPiece, sizes[r] - at)), MPI_BYTE, int(r), kTag, MPI_COMM_WORLD,
                &requests.emplace_back());
  MPI_Waitall(int(requests.size()), requests.data(), MPI_STATUSES_IGNORE);
  return got;
}

void Comm::sumInPlace(std::vector<uint64_t>& v) { reduce(v, MPI_UINT64_T, MPI_SUM); }
void Comm::sumInPlace(std::vector<double>& v) { reduce(v, MPI_DOUBLE, MPI_SUM); }
void Comm::minInPlace(std::vector<double>& v) { reduce(v, MPI_DOUBLE, MPI_MIN); }
void Comm::maxInPlace(std::vector<double>& v) { reduce(v, MPI_DOUBLE, MPI_MAX); }
void Comm::barrier() { MPI_Barrier(MPI_COMM_WORLD); }

Result Comm::agree(const Result& mine, bool secondary) {
  // The lowest rank that failed first-hand, else the lowest that failed at all.
  int key[2] = {!mine && !secondary ? rank_ : size_, mine ? size_ : rank_};
  MPI_Allreduce(MPI_IN_PLACE, key, 2, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  if (key[1] == size_) return Result::success();
  const int root = key[0] < size_ ? key[0] : key[1];
  int status = int(mine.status);
  uint64_t length = mine.message.size();
  MPI_Bcast(&status, 1, MPI_INT, root, MPI_COMM_WORLD);
  MPI_Bcast(&length, 1, MPI_UINT64_T, root, MPI_COMM_WORLD);
  std::string message = rank_ == root ? mine.message : std::string(length, '\0');
  MPI_Bcast(message.data(), int(length), MPI_CHAR, root, MPI_COMM_WORLD);
  if (size_ > 1) message = "rank " + std::to_string(root) + ": " + message;
  return fail(Status(status), message);
}

#else  // built without MPI

bool mpiAvailable() { return false; }
Result Comm::world(std::unique_ptr<Comm>&) {
  return fail(Status::Unsupported, "this tetstream was built without MPI (install libopenmpi-dev and rebuild)");
}
Comm::~Comm() = default;
void Comm::send(int, int, const Bytes&, bool) {}
bool Comm::receive(int, int, Bytes&) { return false; }
std::vector<Bytes> Comm::allGather(const Bytes& mine) { return {mine}; }
std::vector<Bytes> Comm::allToAll(const std::vector<Bytes>& sendTo) { return sendTo; }
void Comm::sumInPlace(std::vector<uint64_t>&) {}
void Comm::sumInPlace(std::vector<double>&) {}
void Comm::minInPlace(std::vector<double>&) {}
void Comm::maxInPlace(std::vector<double>&) {}
void Comm::barrier() {}
Result Comm::agree(const Result& mine, bool) { return mine; }

#endif

}  // namespace tetstream::dist
