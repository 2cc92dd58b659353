#!/usr/bin/env bash
# Fails when the tree names a path of one particular machine, or when a shipped
# scene reaches outside the checkout for a file. Scenes name fetched data as
# "$data/..." (docs/scene-format.md); everything else lives in the repository.
# Run by CTest (pathlab_portable) and usable by hand: tools/check-portable.sh
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
cd "$repo"

if git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  mapfile -t files < <(git ls-files --cached --others --exclude-standard)
else
  mapfile -t files < <(find . -type f -not -path './.git/*' -not -path './build*' -not -path './data/*' | sed 's|^\./||')
fi

self="tools/check-portable.sh"
status=0
# Home and work folders of particular machines, and folders beside the checkout.
machine='(^|[^A-Za-z0-9_.$~-])/(work|home|root|Users|mnt|media|scratch|srv)/|[A-Za-z]:\\\\|\.\./shared|\.\./\.\./\.\.'
for f in "${files[@]}"; do
  [ "$f" = "$self" ] && continue
  [ -f "$f" ] || continue
  if hits=$(grep -I -n -E "$machine" "$f"); then
    while IFS= read -r hit; do echo "$f:$hit: names a path outside the project" >&2; done <<<"$hits"
    status=1
  fi
done

# Every "file" a JSON scene names is "$data/..." or stays inside the checkout.
for f in "${files[@]}"; do
  case "$f" in *.json) ;; *) continue ;; esac
  [ -f "$f" ] || continue
  while IFS= read -r name; do
    case "$name" in '$data/'*) continue ;; esac
    target="$(realpath -m "$(dirname "$f")/$name")"
    case "$target" in "$repo"/*) ;; *) echo "$f: \"$name\" is outside the checkout; name fetched data as \"\$data/...\"" >&2; status=1 ;; esac
  done < <(grep -o -E '"file"[[:space:]]*:[[:space:]]*"[^"]*"' "$f" | sed -E 's/.*:[[:space:]]*"([^"]*)"/\1/')
done

if [ "$status" -eq 0 ]; then echo "pathlab: no machine-specific paths in ${#files[@]} files"; fi
exit "$status"
