#include "dist/base_error.h"

#include <algorithm>
#include <cmath>

#include "dist/tet_grid.h"

namespace tetstream::dist {

void measureBaseError(Comm& comm, const TetMesh* base, const PartMesh& input, int field, double& rms, double& max) {
  Bytes mine;
  if (base) {
    Writer w(mine);
    w.putVector(base->positions);
    w.putVector(base->tets);
    w.putVector(base->fields[size_t(field)].values);
  }
  TetMesh shared;
  std::vector<float> values;
  for (const Bytes& b : comm.allGather(mine)) {
    if (b.empty()) continue;
    Reader in(b);
    shared.positions = in.getVector<float>();
    shared.tets = in.getVector<uint32_t>();
    values = in.getVector<float>();
  }
  std::vector<double> sums(2, 0), largest(1, 0);  // squared errors, vertices; the largest
  if (!shared.tets.empty() && values.size() == shared.vertexCount()) {
    const TetGrid grid(shared);
    const std::vector<float>& samples = input.mesh.fields[size_t(field)].values;
    for (uint32_t v = 0; v < input.mesh.vertexCount(); ++v) {
      TetGrid::Location l;
      if (!input.owned[v] || !std::isfinite(samples[v]) || !grid.locate(&input.mesh.positions[3 * size_t(v)], l))
        continue;
      double at = 0;
      for (int k = 0; k < 4; ++k) at += l.w[k] * values[l.vertex[k]];
      if (!std::isfinite(at)) continue;
      const double e = std::abs(at - samples[v]);
      sums[0] += e * e;
      sums[1] += 1;
      largest[0] = std::max(largest[0], e);
    }
  }
  comm.sumInPlace(sums);
  comm.maxInPlace(largest);
  rms = sums[1] > 0 ? std::sqrt(sums[0] / sums[1]) : 0;
  max = largest[0];
}

}  // namespace tetstream::dist
