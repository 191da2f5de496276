#!/usr/bin/env bash
# Executions and findings per fuzz target, summed over every run in tests/fuzz/executions.tsv.
cd "$(dirname "$0")"
printf "%-12s %14s %9s %8s\n" target executions seconds findings
awk -F'\t' '!/^#/ { e[$2] += $4; s[$2] += $3; f[$2] += $5 }
  END { for (t in e) printf "%-12s %14d %9d %8d\n", t, e[t], s[t], f[t] }' executions.tsv | sort -k1,1
