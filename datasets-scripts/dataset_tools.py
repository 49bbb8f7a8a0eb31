#!/usr/bin/env python3
"""Helpers for fetch_datasets.sh (standard library only).

  dataset_tools.py cranium-sidecar MAIN.plist   -> JSON sidecar for InVesalius' matrix.dat
  dataset_tools.py plt-sidecar FILE.plt         -> JSON sidecar for a gOpenMol .plt grid

Sidecars follow visopt's raw format: {"dims", "type", "spacing", "origin", "endian",
"headerBytes"}; data is x fastest.
"""
import json
import plistlib
import struct
import sys


def cranium_sidecar(plist_path):
    with open(plist_path, "rb") as f:
        main = plistlib.load(f)
    matrix = main["matrix"]
    if matrix.get("dtype") != "int16":
        raise SystemExit("unexpected matrix dtype %r" % matrix.get("dtype"))
    nz, ny, nx = (int(v) for v in matrix["shape"])  # numpy C order: z, y, x
    spacing = [float(v) for v in main["spacing"]]
    return {"dims": [nx, ny, nz], "type": "int16", "spacing": spacing,
            "origin": [0.0, 0.0, 0.0], "endian": "little", "headerBytes": 0}


def plt_sidecar(plt_path):
    with open(plt_path, "rb") as f:
        head = f.read(44)
    rank, _surface, nz, ny, nx = struct.unpack("<5i", head[:20])
    if rank != 3:
        raise SystemExit("not a little-endian gOpenMol plt (rank %d)" % rank)
    zmin, zmax, ymin, ymax, xmin, xmax = struct.unpack("<6f", head[20:44])
    dims = [nx, ny, nz]
    lo = [xmin, ymin, zmin]
    hi = [xmax, ymax, zmax]
    spacing = [(hi[a] - lo[a]) / dims[a] for a in range(3)]  # extents are cell edges
    origin = [lo[a] + 0.5 * spacing[a] for a in range(3)]
    return {"dims": dims, "type": "float32", "spacing": spacing, "origin": origin,
            "endian": "little", "headerBytes": 44}


def main(argv):
    if len(argv) != 3 or argv[1] not in ("cranium-sidecar", "plt-sidecar"):
        raise SystemExit(__doc__)
    result = cranium_sidecar(argv[2]) if argv[1] == "cranium-sidecar" else plt_sidecar(argv[2])
    print(json.dumps(result, indent=1))


if __name__ == "__main__":
    main(sys.argv)
