#include "io/xdmf_mixed.h"

namespace tetstream::xdmf {

namespace {
constexpr int kPolyhedron = 0x10;  // its nodes come face by face, each face with its node count
}

Result MixedWalker::walk(std::span<const int64_t> values, bool end, MixedCells& out, size_t& used) {
  const size_t n = values.size();
  used = 0;
  std::vector<int64_t> nodes;
  while (cell_ < keepTo_ && used < n) {
    size_t i = used;
    const std::string cell = where_ + " Topology (Mixed): cell " + std::to_string(cell_);
    // Whether k more values follow. When they do not, the cell runs past these values: `cut` is
    // an error at the end of the topology, else success (the next call walks the cell).
    Result cut = Result::success();
    auto have = [&](uint64_t k, const char* what) {
      if (k <= n - i) return true;
      if (end)
        cut = fail(Status::Truncated, cell + " needs " + std::to_string(k) + " more values for its " + what + ", " +
                                          std::to_string(n - i) + " remain");
      return false;
    };
    const int64_t code = values[i++];
    const TopologyKind* k = kindByCode(code);
    if (!k) return fail(Status::Corrupt, cell + " has the unknown cell type code " + std::to_string(code));
    nodes.clear();
    if (k->code == kPolyhedron) {
      if (!have(1, "face count")) return cut;
      const int64_t faces = values[i++];
      if (faces < 0 || (end && uint64_t(faces) > n - i))
        return fail(Status::Corrupt, cell + " (a polyhedron) declares " + std::to_string(faces) + " faces");
      for (int64_t f = 0; f < faces; ++f) {
        if (!have(1, "face node count")) return cut;
        const int64_t m = values[i++];
        if (m < 0) return fail(Status::Corrupt, cell + ": a polyhedron face of " + std::to_string(m) + " nodes");
        if (!have(uint64_t(m), "face nodes")) return cut;
        nodes.insert(nodes.end(), values.begin() + std::ptrdiff_t(i), values.begin() + std::ptrdiff_t(i + size_t(m)));
        i += size_t(m);
      }
    } else {
      uint64_t count = uint64_t(k->nodes);
      if (count == 0) {
        if (!have(1, "node count")) return cut;
        if (values[i] < 0) return fail(Status::Corrupt, cell + " has a node count of " + std::to_string(values[i]));
        count = uint64_t(values[i++]);
      }
      if (!have(count, "nodes")) return cut;
      nodes.assign(values.begin() + std::ptrdiff_t(i), values.begin() + std::ptrdiff_t(i + count));
      i += count;
    }
    if (cell_ >= keepFrom_) {
      const bool read = k->read && k->code != kPolyhedron;
      if (read || skippedNodes_)
        for (int64_t id : nodes) out.connectivity.push_back(id - base_);
      out.offsets.push_back(int64_t(out.connectivity.size()));
      out.types.push_back(read ? k->vtk : 0);
      if (!read) ++out.notRead[k];
    }
    ++cell_;
    used = i;
  }
  return Result::success();
}

}  // namespace tetstream::xdmf
