#!/usr/bin/env bash
# Prints, one per line and most first, the shared libraries among the run-time
# dependencies of the given libraries that carry the most symbol relocations (at least
# MIN). See cmake/StartupOrder.cmake for why.
#
#   cmake/startup_order.sh READELF MIN LIB...
set -euo pipefail
readelf=$1
min=$2
shift 2
export readelf
{ for seed in "$@"; do ldd "$seed" 2>/dev/null || true; done; } |
  awk '$2 == "=>" && $3 ~ /^\// {print $3}' | sort -u |
  # Symbol relocations only: RELATIVE ones need no lookup.
  xargs -P "$(nproc)" -I{} sh -c \
    '"$readelf" -rW "$1" 2>/dev/null | awk -v lib="$1" '"'"'/R_X86_64_|R_AARCH64_/ && !/_RELATIVE/ {n++} END {print n + 0, lib}'"'"'' _ {} |
  sort -k1,1rn -k2 | awk -v min="$min" '$1 >= min {print $2}'
