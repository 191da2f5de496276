// The processes of a distributed pack (MPI ranks) as the packer sees them: who I am, byte
// messages between ranks, a few collectives, and agreement on failure. Everything the packer
// exchanges goes through here, so the rest of the distributed packer reads like plain C++ and
// no MPI type leaks out of comm.cpp.
//
// Failure: a rank that fails (a bad piece, too little memory) must stop every rank with one
// message and never leave another waiting. Every phase therefore ends in agree(), which all ranks
// call: when any rank failed, all of them return the failure of the lowest failing rank that
// failed first-hand (a rank that failed only because a message from a failed rank said so
// reports "secondary" failures, which agree() passes over), its rank named in the message.
#pragma once
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "status.h"

namespace tetstream::dist {

// Whether this process was started by an MPI launcher (mpirun, mpiexec, srun with PMI/PMIx):
// decided from the environment, before MPI is initialised.
bool launchedByMpi();

// Whether the program was built with MPI.
bool mpiAvailable();

using Bytes = std::vector<uint8_t>;

class Comm {
 public:
  // Initialises MPI for the whole program (once) and returns the world; fails when the program
  // was built without MPI.
  static Result world(std::unique_ptr<Comm>& out);
  ~Comm();

  int rank() const { return rank_; }
  int size() const { return size_; }

  // A message with a status: a rank that failed still sends (secondary = true then), so the
  // receiver does not wait forever; the receiver learns of the failure from it.
  void send(int to, int tag, const Bytes& data, bool failed = false);
  // False when the sender had failed (data then empty).
  bool receive(int from, int tag, Bytes& data);

  // Every rank's bytes, in rank order, on every rank.
  std::vector<Bytes> allGather(const Bytes& mine);
  // out[r] = what rank r sent me; sendTo[r] goes to rank r.
  std::vector<Bytes> allToAll(const std::vector<Bytes>& sendTo);
  // Element-wise over all ranks, in place.
  void sumInPlace(std::vector<uint64_t>& values);
  void sumInPlace(std::vector<double>& values);
  void minInPlace(std::vector<double>& values);
  void maxInPlace(std::vector<double>& values);
  void barrier();

  // See the head of this file. `secondary`: this rank failed because another did.
  Result agree(const Result& mine, bool secondary = false);

 private:
  Comm() = default;
  int rank_ = 0, size_ = 1;
};

// Plain values in and out of byte messages (native byte order: one job runs on one kind of
// machine).
class Writer {
 public:
  explicit Writer(Bytes& out) : out_(out) {}
  template <typename T>
  void put(const T& x) {
    append(&x, sizeof(T));
  }
  template <typename T>
  void putVector(const std::vector<T>& v) {
    put<uint64_t>(v.size());
    append(v.data(), v.size() * sizeof(T));
  }
  void putString(const std::string& s) {
    put<uint64_t>(s.size());
    append(s.data(), s.size());
  }

 private:
  void append(const void* data, size_t bytes) {
    if (bytes == 0) return;
    const size_t at = out_.size();
    out_.resize(at + bytes);
    std::memcpy(out_.data() + at, data, bytes);
  }
  Bytes& out_;
};

// Reads what Writer wrote; every read is checked against the bytes left (ok() false after any
// read past the end, which returns zeros).
class Reader {
 public:
  explicit Reader(const Bytes& in) : in_(in) {}
  template <typename T>
  T get() {
    T x{};
    if (!take(&x, sizeof(T))) return T{};
    return x;
  }
  template <typename T>
  std::vector<T> getVector() {
    const uint64_t n = get<uint64_t>();
    std::vector<T> v;
    if (!ok_ || n > (in_.size() - at_) / sizeof(T)) {
      ok_ = false;
      return v;
    }
    v.resize(n);
    take(v.data(), n * sizeof(T));
    return v;
  }
  std::string getString() {
    const std::vector<char> c = getVector<char>();
    return std::string(c.begin(), c.end());
  }
  bool ok() const { return ok_; }
  bool atEnd() const { return ok_ && at_ == in_.size(); }

 private:
  bool take(void* to, size_t n);
  const Bytes& in_;
  size_t at_ = 0;
  bool ok_ = true;
};

}  // namespace tetstream::dist
