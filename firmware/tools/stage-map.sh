#!/usr/bin/env bash
# stage-map.sh ELF STAGES > MAP
#
# Writes the address map insncount.c's map= argument reads: every instruction address in
# .text ranged to the pipeline stage it belongs to, from the ELF's DWARF line and inlining
# tables (binutils addr2line -i), so no function needs #[inline(never)] for its cost to be
# measured. STAGES has lines "NAME EXTENDED-REGEX"; for each address the frames are tried
# from the innermost inlined function outwards, and the first frame matching any stage's
# regex (tried in file order) names the stage; a frame whose first match is named "skip"
# is passed over (code shared by two stages, such as the CRC, belongs to its caller). Addresses no stage claims are "other" when
# some frame is the firmware's own code (the loop, semihosting I/O, start-up) and
# "inherit" otherwise (out-of-line helpers such as libm, memcpy, core::fmt: charged to the
# stage that called them).
set -euo pipefail
elf=$1
stages=$2
read -r start size < <(readelf -SW "$elf" | awk '{for (i = 1; i <= NF; i++) if ($i == ".text") print $(i + 2), $(i + 4)}')
[ -n "${start:-}" ] || { echo "stage-map.sh: no .text section in $elf" >&2; exit 1; }
awk -v s=$((16#$start)) -v n=$((16#$size)) 'BEGIN { for (a = s; a < s + n; a += 2) printf "0x%08x\n", a }' |
  addr2line -a -f -i -C -e "$elf" |
  awk -v stages="$stages" '
    BEGIN {
      ns = 0
      while ((getline line < stages) > 0) {
        if (line ~ /^[ \t]*(#|$)/) continue
        split(line, f, /[ \t]+/)
        name[ns] = f[1]; re[ns] = substr(line, index(line, f[2])); ns++
      }
      own = "curbtrace_firmware|cortex_m_rt|cortex_m_semihosting|cortex_m::|^Reset$|HardFault|DefaultHandler|^main$"
    }
    function classify(   i, k) {
      for (i = 0; i < nf; i++)
        for (k = 0; k < ns; k++)
          if (frame[i] ~ re[k]) {
            if (name[k] != "skip") return name[k]
            break
          }
      for (i = 0; i < nf; i++) if (frame[i] ~ own) return "other"
      return "inherit"
    }
    function hex(h,   v, i) {
      v = 0; h = tolower(substr(h, 3))
      for (i = 1; i <= length(h); i++) v = v * 16 + index("0123456789abcdef", substr(h, i, 1)) - 1
      return v
    }
    function flush(   c) {
      if (addr == "") return
      c = classify()
      if (c != cur) {
        if (cur != "") printf "0x%08x 0x%08x %s\n", lo, addr, cur
        cur = c; lo = addr
      }
    }
    /^0x[0-9a-f]+$/ { flush(); addr = hex($0); nf = 0; odd = 1; next }
    { if (odd) frame[nf++] = $0; odd = !odd }
    END { flush(); printf "0x%08x 0x%08x %s\n", lo, addr + 2, cur }
  '
