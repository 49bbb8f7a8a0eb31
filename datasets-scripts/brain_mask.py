#!/usr/bin/env python3
"""A brain mask for the brainsmall MRI head (an importance volume for `visopt optimize`).

usage: brain_mask.py IN.raw IN.raw.json OUT.raw

Classic skull stripping in four steps, no libraries: tissue = voxels above a threshold; erode
it until the brain no longer touches the scalp through the dark skull and CSF; keep the largest
connected component (the brain); dilate it back by as many voxels. Writes uint8 0/1 with a
JSON sidecar (OUT.raw.json) on the input's grid. The threshold and erosion are stated below and
were read off the scan's histogram and slices, not tuned to any optimisation result.
"""
import json
import sys
from collections import deque

THRESHOLD = 45  # 8-bit intensity: brain tissue above, skull and CSF below (T1)
EROSION = 3     # voxels


def main():
    src, side, out = sys.argv[1:4]
    meta = json.load(open(side))
    nx, ny, nz = meta["dims"]
    data = open(src, "rb").read()[meta.get("headerBytes", 0):]
    n = nx * ny * nz
    if len(data) < n:
        sys.exit(f"{src}: holds {len(data)} voxels, its sidecar describes {n}")
    tissue = bytearray(1 if data[i] > THRESHOLD else 0 for i in range(n))
    sx, sy = 1, nx
    sz = nx * ny

    def neighbours(v):
        i, j, k = v % nx, (v // nx) % ny, v // sz
        if i > 0: yield v - sx
        if i < nx - 1: yield v + sx
        if j > 0: yield v - sy
        if j < ny - 1: yield v + sy
        if k > 0: yield v - sz
        if k < nz - 1: yield v + sz

    def erode(m):
        outm = bytearray(m)
        for v in range(n):
            if m[v] and any(not m[u] for u in neighbours(v)):
                outm[v] = 0
        return outm

    def dilate(m):
        outm = bytearray(m)
        for v in range(n):
            if not m[v] and any(m[u] for u in neighbours(v)):
                outm[v] = 1
        return outm

    core = tissue
    for _ in range(EROSION):
        core = erode(core)
    # Largest 6-connected component.
    label = bytearray(n)
    best, bestSize = None, 0
    for start in range(n):
        if not core[start] or label[start]:
            continue
        comp = [start]
        label[start] = 1
        queue = deque([start])
        while queue:
            v = queue.popleft()
            for u in neighbours(v):
                if core[u] and not label[u]:
                    label[u] = 1
                    comp.append(u)
                    queue.append(u)
        if len(comp) > bestSize:
            best, bestSize = comp, len(comp)
    mask = bytearray(n)
    for v in best or []:
        mask[v] = 1
    for _ in range(EROSION):
        mask = dilate(mask)
    mask = bytearray(1 if mask[v] and tissue[v] else 0 for v in range(n))
    with open(out, "wb") as f:
        f.write(bytes(1 if m else 0 for m in mask))
    sidecar = dict(meta)
    sidecar["headerBytes"] = 0
    sidecar["type"] = "uint8"
    with open(out + ".json", "w") as f:
        json.dump(sidecar, f)
    print(f"{out}: {sum(mask)} brain voxels of {n}")


if __name__ == "__main__":
    main()
