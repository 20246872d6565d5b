#!/usr/bin/env bash
# profile.sh ELF PCS [DEPTH] — a flat profile from insncount's pcs=FILE output: executed
# instructions per function, naming each address by its innermost inlined function
# (DEPTH=2: "caller <- innermost", and so on), largest first.
set -euo pipefail
elf=$1; pcs=$2; depth=${3:-1}
awk '{ print $1 }' "$pcs" | addr2line -a -f -i -C -e "$elf" |
  awk -v depth="$depth" -v pcs="$pcs" '
    BEGIN { while ((getline l < pcs) > 0) { split(l, f, " "); cnt[f[1]] = f[2] } }
    function flush() { if (addr != "") total[key] += cnt[addr] }
    /^0x[0-9a-f]+$/ { flush(); addr = $0; key = ""; nf = 0; odd = 1; next }
    { if (odd) { nf++; if (nf <= depth) key = (key == "" ? "" : key " <- ") $0 } odd = !odd }
    END { flush(); for (k in total) printf "%12d  %s\n", total[k], k }' |
  sort -rn
