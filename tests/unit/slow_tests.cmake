# Unit tests that take more than about two seconds each (ctest -j2, release build): labelled
# `slow`, every other unit test `fast`. npm run test:fast (ctest -L fast) leaves these out;
# npm test runs them. A gtest filter: names joined by ':', '*' as a wildcard.
set(TETSTREAM_SLOW_TESTS
  LevelError.MeasuredLevelErrorsMatchBruteForce
  Simplify.RegionsGiveValidLevelsAndTheSameQuality
  Simplify.CostPerRemovedTetGivesALowerErrorAtTheSameTets
  Simplify.GradedMeshKeepsTheFarFieldWhereIsosurfacesAre
  SimplifyRefit.FittedValuesLowerTheFieldErrorOfCoarseLevels
  PackRoundTrip.LastChunksHalveTowardsTheEnd
  IntervalTree.BenchmarkHarmonic64
  IntervalTree.DynamicQueriesEqualBruteForce
  IncrementalIso.BenchmarkHarmonic64)
list(JOIN TETSTREAM_SLOW_TESTS ":" TETSTREAM_SLOW_TESTS)
