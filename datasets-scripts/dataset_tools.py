#!/usr/bin/env python3
"""Helpers for fetch_datasets.sh (standard library only).

  dataset_tools.py cranium-sidecar MAIN.plist   -> JSON sidecar for InVesalius' matrix.dat
  dataset_tools.py plt-sidecar FILE.plt         -> JSON sidecar for a gOpenMol .plt grid
  dataset_tools.py nifti-mask IN.nii.gz OUT.raw  -> OUT.raw (+ .json): 0/1 where IN > 0

Sidecars follow visopt's raw format: {"dims", "type", "spacing", "origin", "endian",
"headerBytes"}; data is x fastest.
"""
import gzip
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


def nifti_mask(nii_gz_path, out_path):
    """A 0/1 uint8 raw volume (value > 0) of a gzipped axis-aligned uint8 NIfTI-1, with a sidecar
    on the same world grid as visopt's NIfTI reader gives (NIfTI's RAS frame, from the sform)."""
    data = gzip.open(nii_gz_path).read()
    if struct.unpack("<i", data[:4])[0] != 348 or data[344:347] != b"n+1":
        raise SystemExit("%s: not a little-endian single-file NIfTI-1" % nii_gz_path)
    dim = struct.unpack("<8h", data[40:56])
    datatype, bitpix = struct.unpack("<hh", data[70:74])
    offset = int(struct.unpack("<f", data[108:112])[0])
    sform_code = struct.unpack("<h", data[254:256])[0]
    srow = struct.unpack("<12f", data[280:328])
    if dim[0] != 3 or datatype != 2 or bitpix != 8:
        raise SystemExit("%s: expected a 3-D uint8 volume" % nii_gz_path)
    off_diagonal = [srow[r * 4 + c] for r in range(3) for c in range(3) if r != c]
    diagonal = [srow[0], srow[5], srow[10]]
    if sform_code <= 0 or any(off_diagonal) or any(v <= 0 for v in diagonal):
        raise SystemExit("%s: expected a positive axis-aligned sform" % nii_gz_path)
    dims = list(dim[1:4])
    n = dims[0] * dims[1] * dims[2]
    if len(data) < offset + n:
        raise SystemExit("%s: truncated" % nii_gz_path)
    sidecar = {"dims": dims, "type": "uint8", "spacing": diagonal,
               "origin": [srow[3], srow[7], srow[11]], "endian": "little", "headerBytes": 0}
    with open(out_path, "wb") as f:
        f.write(bytes(1 if v else 0 for v in data[offset:offset + n]))
    with open(out_path + ".json", "w") as f:
        json.dump(sidecar, f)


def main(argv):
    if len(argv) == 4 and argv[1] == "nifti-mask":
        nifti_mask(argv[2], argv[3])
        return
    if len(argv) != 3 or argv[1] not in ("cranium-sidecar", "plt-sidecar"):
        raise SystemExit(__doc__)
    result = cranium_sidecar(argv[2]) if argv[1] == "cranium-sidecar" else plt_sidecar(argv[2])
    print(json.dumps(result, indent=1))


if __name__ == "__main__":
    main(sys.argv)
