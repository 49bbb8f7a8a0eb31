#!/usr/bin/env bash
# Fails (listing the files) when a tracked C++/CUDA source differs from what clang-format makes
# of it with the project's .clang-format. Fix with: git ls-files '*.cpp' '*.h' '*.cu' | xargs
# clang-format -i
set -euo pipefail
cd "$(dirname "$0")/.."
mapfile -t files < <(git ls-files '*.cpp' '*.h' '*.cu' '*.cuh')
bad=()
for f in "${files[@]}"; do
  clang-format --dry-run --Werror "$f" >/dev/null 2>&1 || bad+=("$f")
done
if ((${#bad[@]})); then
  echo "visopt: not formatted with clang-format (.clang-format):" >&2
  printf '  %s\n' "${bad[@]}" >&2
  exit 1
fi
echo "visopt: ${#files[@]} sources formatted"
