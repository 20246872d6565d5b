#!/usr/bin/env python3
"""stretch.py KERNEL_OUT STREAM POINTS OUT — the densest stretch of a stream, as a stream.

KERNEL_OUT is `curbtrace kernel STREAM -o KERNEL_OUT` in candidates mode (one kind-4 packet
per line, docs/wire-format.md). Finds the run of consecutive lines of at least POINTS points
with the largest share inside the region of interest (the lines whose kernel work per point
is largest: the stretch a real-time run is limited by) and writes OUT: STREAM's config
packets before it, then its points packets whose base time lies within those lines' time
span (config packets inside it are left out). Prints the lines, their points and the share inside.
"""
import struct
import sys

out_path, stream_path, want, dst = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4]
out = open(out_path, "rb").read()
lines = []  # (start_time_ns, points, inside)
at = 0
while at < len(out):
    kind, length = out[at + 3], struct.unpack_from("<H", out, at + 4)[0]
    if kind != 4:
        sys.exit(f"{out_path}: packet kind {kind} at {at}: not a candidates-mode output")
    t, = struct.unpack_from("<Q", out, at + 16)
    n, = struct.unpack_from("<H", out, at + 32)
    outside, = struct.unpack_from("<H", out, at + 50)
    lines.append((t, n, n - outside))
    at += length
best, j, pts, ins = (0.0, 0, 0), 0, 0, 0
for i, (_, n, k) in enumerate(lines):
    pts, ins = pts + n, ins + k
    while pts - lines[j][1] >= want:
        pts, ins, j = pts - lines[j][1], ins - lines[j][2], j + 1
    if pts >= want and ins / pts > best[0]:
        best = (ins / pts, j, i)
share, a, b = best
t0 = lines[a][0]
t1 = lines[b + 1][0] if b + 1 < len(lines) else 2**64
data = open(stream_path, "rb").read()
keep = bytearray()
started = False
at = 0
while at < len(data):
    kind, length = data[at + 3], struct.unpack_from("<H", data, at + 4)[0]
    if kind == 1:
        base, = struct.unpack_from("<Q", data, at + 12)
        if t0 <= base < t1:
            keep += data[at:at + length]
            started = True
    elif kind == 2 and not started:
        # The config packets before the stretch (the ones inside it would only end lines,
        # as the sequence gap at its start does).
        keep += data[at:at + length]
    at += length
open(dst, "wb").write(keep)
n = sum(l[1] for l in lines[a:b + 1])
print(f"lines {a}..{b}: {n} points, {share:.3f} inside the region, {len(keep)} bytes")
