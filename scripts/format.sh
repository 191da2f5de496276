#!/usr/bin/env bash
# clang-format over the project's C++ (.clang-format at the top). `scripts/format.sh` rewrites
# the files; `scripts/format.sh --check` lists the files that differ and fails (npm test runs it).
set -euo pipefail
cd "$(dirname "$0")/.."
mapfile -t files < <(git ls-files 'core/*.cpp' 'core/*.h' 'wasm/*.cpp' 'wasm/*.h' 'tests/*.cpp' 'tests/*.h')
if [ "${1:-}" = --check ]; then
  clang-format --dry-run --Werror "${files[@]}" 2>/dev/null || {
    clang-format --dry-run "${files[@]}" 2>&1 | grep -o '^[^:]*\.\(cpp\|h\)' | sort -u | sed 's/^/  not formatted: /'
    echo "format: run 'bash scripts/format.sh' (clang-format $(clang-format --version | grep -o '[0-9][0-9.]*' | head -1))"
    exit 1
  }
  echo "format: ok (${#files[@]} files)"
else
  clang-format -i "${files[@]}"
fi
