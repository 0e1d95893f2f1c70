#!/usr/bin/env bash
# The C++ sources must be formatted as .clang-format says (Debian's clang-format).
# Usage: scripts/check_format.sh        lists unformatted files, exit 1 if any
#        scripts/check_format.sh --fix  rewrites them in place (make format)
set -euo pipefail
cd "$(dirname "$0")/.."
command -v clang-format >/dev/null || { echo "format: clang-format is missing (make deps installs it)" >&2; exit 1; }
dirs=(src include apps python tests bench fuzz examples)
if git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  mapfile -t files < <(git ls-files -co --exclude-standard -- "${dirs[@]}" | grep -E '\.(cpp|h|h\.in)$')
else
  mapfile -t files < <(find "${dirs[@]}" -type f \( -name '*.cpp' -o -name '*.h' -o -name '*.h.in' \) | sort)
fi
if [[ ${1:-} == --fix ]]; then
  clang-format -i "${files[@]}"
  exit 0
fi
bad=()
for f in "${files[@]}"; do
  [[ -f $f ]] || continue
  clang-format --dry-run --Werror "$f" >/dev/null 2>&1 || bad+=("$f")
done
if ((${#bad[@]})); then
  echo "format: ${#bad[@]} file(s) not formatted as .clang-format says (run 'make format'):" >&2
  printf '  %s\n' "${bad[@]}" >&2
  exit 1
fi
echo "format: ${#files[@]} files formatted"
