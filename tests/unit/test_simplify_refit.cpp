// Values of coarse levels (pack/simplify_refit.cpp): fitted to the region each vertex stands for,
// fitted again at the end as a least-squares minimum, samples that are not numbers left out.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "dataset.h"
#include "pack/packer.h"
#include "pack/simplify.h"
#include "test_helpers.h"

using namespace tetstream;
using namespace tetstream::test;

namespace {

// The same mesh simplified to 5% of its vertices with the final fit of the values and without.
void simplifyWithAndWithoutRefit(const TetMesh& m, SimplifyResult& refit, SimplifyResult& once) {
  SimplifyOptions o;
  o.targetVertices = m.vertexCount() / 20;
  ASSERT_TRUE(simplifyMesh(m, o, refit));
  o.refitValues = false;
  ASSERT_TRUE(simplifyMesh(m, o, once));
}

}  // namespace

// Coarse levels carry values fitted to the region each vertex stands for (SimplifyOptions::
// fitValues): a lower field error than keeping the samples; --samples keeps the input's values
// at every level, and fields that did not steer keep them either way.
TEST(SimplifyRefit, FittedValuesLowerTheFieldErrorOfCoarseLevels) {
  const TetMesh m = harmonic(20);
  PackOptions o;
  o.baseFraction = 0.05;
  o.minBaseVertices = 0;
  const std::string fitDir = pack("fitted", m, o);
  o.fitValues = false;
  const std::string sampleDir = pack("samples", m, o);
  Dataset fit, samples;
  ASSERT_TRUE(loadPackedDir(fitDir, fit, 1));
  ASSERT_TRUE(loadPackedDir(sampleDir, samples, 1));
  const TetMesh& a = fit.pm.mesh;
  const TetMesh& b = samples.pm.mesh;
  const double fitRms = fieldRms(m, a, 0), sampleRms = fieldRms(m, b, 0);
  RecordProperty("fitted_rms", std::to_string(fitRms));
  RecordProperty("sampled_rms", std::to_string(sampleRms));
  EXPECT_LT(fitRms, 0.9 * sampleRms);
  // Which base values are input samples: every one with --samples, and every one of the field
  // that did not steer; the fitted field has values of its own.
  const Quantizer& q = fit.quant;  // the same grid for both packs
  auto key = [&](const float* p) {
    return std::array<uint32_t, 3>{q.position[0].quantize(p[0]), q.position[1].quantize(p[1]),
                                   q.position[2].quantize(p[2])};
  };
  std::map<std::array<uint32_t, 3>, uint32_t> at;
  for (uint32_t v = 0; v < m.vertexCount(); ++v) at[key(&m.positions[3 * v])] = v;
  auto sampledCount = [&](const TetMesh& level, int f) {
    uint32_t n = 0;
    for (uint32_t v = 0; v < level.vertexCount(); ++v) {
      const uint32_t w = at.at(key(&level.positions[3 * v]));
      // The input's value on the quantization grid: within half a step (and float rounding).
      n += std::abs(level.fields[size_t(f)].values[v] - m.fields[size_t(f)].values[w]) <=
           0.51f * q.field[size_t(f)].step;
    }
    return n;
  };
  EXPECT_EQ(sampledCount(b, 0), b.vertexCount());
  EXPECT_EQ(sampledCount(a, 1), a.vertexCount());
  EXPECT_LT(sampledCount(a, 0), a.vertexCount() / 2);
}

// Samples that are not numbers (simulations write NaN for "no value") take no part in the final
// fit: the other values still get fitted, and none becomes NaN that was not before.
TEST(SimplifyRefit, RefitIgnoresSamplesThatAreNotNumbers) {
  TetMesh m = harmonic(12);
  for (uint32_t v = 100; v < m.vertexCount(); v += 97) m.fields[0].values[v] = std::nanf("");
  SimplifyResult refit, once;
  ASSERT_NO_FATAL_FAILURE(simplifyWithAndWithoutRefit(m, refit, once));
  uint32_t changed = 0;
  for (uint32_t v = 0; v < m.vertexCount(); ++v) {
    if (!refit.vertexAlive[v]) continue;
    if (std::isfinite(once.values[v])) {
      EXPECT_TRUE(std::isfinite(refit.values[v])) << "vertex " << v;
    }
    changed += refit.values[v] != once.values[v];
  }
  EXPECT_GT(changed, 10u);
}

// At the end the values of the vertices that stand for others are fitted again, together, to the
// input field at every input vertex (SimplifyOptions::refitValues): the RMS there drops, and it
// is a least-squares minimum: moving any of those values either way makes it worse. Vertices that
// stand only for themselves keep their samples (no split would restore another value).
TEST(SimplifyRefit, RefitValuesMinimiseTheErrorAtTheInputVertices) {
  const TetMesh m = harmonic(14);
  SimplifyResult refit, once;
  ASSERT_NO_FATAL_FAILURE(simplifyWithAndWithoutRefit(m, refit, once));
  ASSERT_EQ(refit.log.j, once.log.j);  // the same collapses: only values differ
  TetMesh a = coarseMesh(m, refit);
  const double refitRms = fieldRms(m, a, 0), onceRms = fieldRms(m, coarseMesh(m, once), 0);
  RecordProperty("refit_rms", std::to_string(refitRms));
  RecordProperty("per_collapse_rms", std::to_string(onceRms));
  EXPECT_LT(refitRms, 0.97 * onceRms);

  // The least-squares conditions: for each value that stands for others, the derivative of the
  // summed squared error, Σ w_v·(coarse − input) over the input points around it, is zero, up to
  // the float rounding of the values (and of one sign at the bounds of the field's range).
  std::vector<uint32_t> coarseOf(m.vertexCount(), ~0u);
  for (uint32_t v = 0, c = 0; v < m.vertexCount(); ++v)
    if (refit.vertexAlive[v]) coarseOf[v] = c++;
  std::vector<double> gradient(a.vertexCount(), 0.0), curvature(a.vertexCount(), 0.0);
  const std::vector<float>& value = a.fields[0].values;
  for (uint32_t v = 0; v < m.vertexCount(); ++v) {
    uint32_t tet = 0;
    double w[4] = {};
    const double best = bestTet(a, &m.positions[3 * v], tet, w);
    ASSERT_GT(best, -1e-6) << "input vertex " << v << " inside the coarse mesh";
    const uint32_t* c = &a.tets[4 * tet];
    double residual = -double(m.fields[0].values[v]);
    for (int k = 0; k < 4; ++k) residual += w[k] * value[c[k]];
    for (int k = 0; k < 4; ++k) {
      gradient[c[k]] += w[k] * residual;
      curvature[c[k]] += w[k] * w[k];
    }
  }
  const Range range = computeRange(m.fields[0].values);
  std::vector<uint8_t> standsForOthers(m.vertexCount(), 0);
  for (uint32_t j : refit.log.j) standsForOthers[j] = 1;
  uint32_t free = 0;
  for (uint32_t v = 0; v < m.vertexCount(); ++v) {
    if (!refit.vertexAlive[v]) continue;
    const uint32_t c = coarseOf[v];
    if (!standsForOthers[v]) {
      EXPECT_EQ(refit.values[v], m.fields[0].values[v]) << "vertex " << v << " keeps its sample";
      continue;
    }
    ++free;
    const double g = gradient[c], tolerance = 1e-5 * curvature[c] + 1e-9;
    if (value[c] <= range.min)
      EXPECT_GT(g, -tolerance) << "vertex " << v << " held at the minimum";
    else if (value[c] >= range.max)
      EXPECT_LT(g, tolerance) << "vertex " << v << " held at the maximum";
    else
      EXPECT_NEAR(g, 0.0, tolerance) << "vertex " << v;
  }
  EXPECT_GT(free, 10u);
}
