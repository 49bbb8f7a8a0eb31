#!/usr/bin/env python3
"""Writes a world-space mask of stand-in continents for builtin:earth-mantle (paper 000, Fig. 9).

Our earth-mantle scene has a uniform crust, no continents; paper 000's Fig. 9 keeps the Earth's
landmasses with a world-space mask. This mask stands in for them: five fixed caps on the sphere
(directions from the grid's centre), their rims made irregular by low-frequency ripples. Every
voxel whose direction falls inside a cap is non-zero, whatever its radius, so the mask keeps the
crust there. Written as uint8 raw with the JSON sidecar visopt reads (mask.raw + mask.raw.json).

usage: continents_mask.py N OUT.raw     (N: the scene's resolution, 128 by default in visopt)
"""
import json
import math
import sys

# (azimuth, elevation, half-angle) in degrees: fixed, so the figure is the same every run.
CAPS = [(20, 35, 28), (-40, 10, 24), (110, -20, 32), (-130, 40, 22), (60, -55, 20)]


def unit(az, el):
    a, e = math.radians(az), math.radians(el)
    return (math.cos(e) * math.cos(a), math.cos(e) * math.sin(a), math.sin(e))


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__.strip().splitlines()[-1])
    n, out = int(sys.argv[1]), sys.argv[2]
    caps = [(unit(az, el), math.radians(half)) for az, el, half in CAPS]
    c = (n - 1) / 2.0
    data = bytearray(n * n * n)
    for z in range(n):
        for y in range(n):
            row = (z * n + y) * n
            for x in range(n):
                v = (x - c, y - c, z - c)
                r = math.sqrt(v[0] ** 2 + v[1] ** 2 + v[2] ** 2)
                if r < 1e-6:
                    continue
                d = (v[0] / r, v[1] / r, v[2] / r)
                ripple = 0.12 * math.sin(5 * d[0] + 2 * d[1]) * math.cos(4 * d[2] - d[0])
                for axis, half in caps:
                    cos_angle = axis[0] * d[0] + axis[1] * d[1] + axis[2] * d[2]
                    if math.acos(max(-1.0, min(1.0, cos_angle))) < half * (1 + ripple):
                        data[row + x] = 1
                        break
    with open(out, "wb") as f:
        f.write(data)
    with open(out + ".json", "w") as f:
        json.dump({"dims": [n, n, n], "type": "uint8", "spacing": [1, 1, 1],
                   "origin": [0, 0, 0]}, f)


if __name__ == "__main__":
    main()
