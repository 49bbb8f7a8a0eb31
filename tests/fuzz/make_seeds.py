#!/usr/bin/env python3
"""Seed corpora for the libFuzzer targets (tests/fuzz/CMakeLists.txt), one folder per target:

- small valid files of every format, written here (the same seeds as mutate_inputs.py, plus a
  DICOM slice, a PLT and a PNG);
- crops of the real files datasets-scripts/fetch_datasets.sh puts in DATA (when present): the
  real headers of skull_2.9.inr, colin27.nii.gz and nAChR_M2_water.plt with their dimensions
  cut to an 8 x 8 x 4 block from the middle of the real data, the real raw sidecars, the first
  faces of head.off; small seeds keep each execution short;
- the transfer functions in resources/ (visopt and ParaView format) and the sessions in
  tests/fuzz/seeds/session (one written by visopt with every section, including a world mask,
  and the older versions 1 and 2 that go through the migrations).

  python3 tests/fuzz/make_seeds.py OUT [--data data]
"""
import argparse, array, glob, gzip, os, re, shutil, struct, sys, zlib

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from mutate_inputs import mesh_seeds, volume_seeds  # noqa: E402

VOLUME_TARGETS = {'.nii': 'nifti', '.mha': 'metaimage', '.nrrd': 'nrrd', '.vtk': 'vtk_legacy',
                  '.vti': 'vti', '.inr': 'inrimage'}
MESH_TARGETS = {'.off': 'off', '.obj': 'obj', '.ply': 'ply', '.stl': 'stl'}
CROP = (8, 8, 4)  # small seeds keep executions short


def put(out, target, name, data):
    d = os.path.join(out, 'fuzz_' + target)
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, name), 'wb') as f:
        f.write(data)


def crop(data, dims, elem, offset=0):
    """The CROP block from the middle of an x-fastest volume of `dims` and `elem` bytes."""
    nx, ny, nz = dims
    cx, cy, cz = CROP
    x0, y0, z0 = (nx - cx) // 2, (ny - cy) // 2, (nz - cz) // 2
    out = bytearray()
    for k in range(z0, z0 + cz):
        for j in range(y0, y0 + cy):
            start = offset + ((k * ny + j) * nx + x0) * elem
            out += data[start:start + cx * elem]
    return bytes(out)


def dicom_slice():
    """One CT slice, explicit VR little endian (as tests/unit/test_volume_io.cpp writes them)."""
    def element(group, elem, vr, value):
        head = struct.pack('<HH', group, elem) + vr
        if vr in (b'OB', b'OW'):
            return head + b'\0\0' + struct.pack('<I', len(value)) + value
        return head + struct.pack('<H', len(value)) + value

    def us(group, elem, v):
        return element(group, elem, b'US', struct.pack('<H', v))

    meta = (element(2, 1, b'OB', b'\0\1') + element(2, 2, b'UI', b'1.2.840.10008.5.1.4.1.1.2\0') +
            element(2, 3, b'UI', b'1.2.3.4.5.6.1\0') + element(2, 0x10, b'UI', b'1.2.840.10008.1.2.1\0'))
    group = element(2, 0, b'UL', struct.pack('<I', len(meta)))
    pixels = array.array('h', ((i * 37) % 2000 - 1000 for i in range(8 * 8))).tobytes()
    ds = (element(8, 0x16, b'UI', b'1.2.840.10008.5.1.4.1.1.2\0') + element(8, 0x60, b'CS', b'CT') +
          element(0x18, 0x50, b'DS', b'2 ') + element(0x20, 0x0D, b'UI', b'1.2.3.4.5\0') +
          element(0x20, 0x0E, b'UI', b'1.2.3.4.5.6\0') + element(0x20, 0x13, b'IS', b'1 ') +
          element(0x20, 0x32, b'DS', b'-20\\-30\\12 ') +
          element(0x20, 0x37, b'DS', b'1\\0\\0\\0\\1\\0 ') + us(0x28, 2, 1) +
          element(0x28, 4, b'CS', b'MONOCHROME2 ') + us(0x28, 0x10, 8) + us(0x28, 0x11, 8) +
          element(0x28, 0x30, b'DS', b'0.5\\0.5 ') + us(0x28, 0x100, 16) + us(0x28, 0x101, 16) +
          us(0x28, 0x102, 15) + us(0x28, 0x103, 1) + element(0x28, 0x1052, b'DS', b'-1024 ') +
          element(0x28, 0x1053, b'DS', b'1 ') + element(0x7FE0, 0x10, b'OW', pixels))
    return b'\0' * 128 + b'DICM' + group + meta + ds


def plt_file(nx, ny, nz, extents, values):
    return struct.pack('<5i6f', 3, 200, nz, ny, nx, *extents) + values


def png_file(w, h):
    rows = b''.join(b'\0' + bytes(c for x in range(w) for c in (x * 16, y * 16, 128))
                    for y in range(h))

    def chunk(kind, body):
        return struct.pack('>I', len(body)) + kind + body + struct.pack('>I', zlib.crc32(kind + body))

    return (b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', w, h, 8, 2, 0, 0, 0)) +
            chunk(b'IDAT', zlib.compress(rows)) + chunk(b'IEND', b''))


def synthetic(out, scratch):
    volume_seeds(scratch, CROP)
    mesh_seeds(scratch)
    for name in sorted(os.listdir(scratch)):
        ext = os.path.splitext(name)[1]
        data = open(os.path.join(scratch, name), 'rb').read()
        if ext in VOLUME_TARGETS:
            put(out, 'volume_' + VOLUME_TARGETS[ext], 'synthetic' + ext, data)
        if ext == '.nii':
            put(out, 'volume_nifti_gz', 'synthetic.nii.gz', gzip.compress(data, mtime=0))
        if ext in MESH_TARGETS:
            put(out, 'mesh_' + MESH_TARGETS[ext], 'octahedron' + ext, data)
    put(out, 'volume_dicom', 'ct-slice.dcm', dicom_slice())
    values = array.array('f', (float((i * 13) % 97) / 97 for i in range(8 * 8 * 4))).tobytes()
    put(out, 'volume_plt', 'synthetic.plt', plt_file(8, 8, 4, (0, 2, 0, 4, 0, 4), values))
    put(out, 'volume_raw_sidecar', 'int16.raw.json',
        b'{"dims":[16,16,8],"type":"int16","spacing":[1,1,2],"origin":[0,0,0],"endian":"little"}')
    put(out, 'volume_raw_sidecar', 'header-bytes.raw.json',
        b'{"dims":[8,8,4],"type":"float32","headerBytes":3072,"endian":"big"}')
    put(out, 'volume_raw_sidecar', 'uint8-direction.raw.json',
        b'{"dims":[32,16,16],"type":"uint8","headerBytes":0,'
        b'"direction":[0,1,0,-1,0,0,0,0,1]}')
    put(out, 'png', 'gradient.png', png_file(16, 8))
    for path in glob.glob(os.path.join(HERE, '..', '..', 'resources', 'transfer-functions', '*')):
        put(out, 'transfer_function', os.path.basename(path), open(path, 'rb').read())
    for path in glob.glob(os.path.join(HERE, 'seeds', 'session', '*')):
        put(out, 'session', os.path.basename(path), open(path, 'rb').read())


def from_real_data(out, data):
    found = []
    inr = os.path.join(data, 'skull_2.9.inr')
    if os.path.exists(inr):
        blob = open(inr, 'rb').read()
        head = blob[:256].decode('latin-1')
        dims = [int(re.search(k + r'=(\d+)', head).group(1)) for k in ('XDIM', 'YDIM', 'ZDIM')]
        bits = int(re.search(r'PIXSIZE=(\d+)', head).group(1))
        for k, v in zip(('XDIM', 'YDIM', 'ZDIM'), CROP):
            head = re.sub(k + r'=\d+', '%s=%d' % (k, v), head)
        head = head[:head.index('##}')].rstrip('\n') + '\n'
        head = head + '\n' * (252 - len(head)) + '##}\n'
        put(out, 'volume_inrimage', 'skull-crop.inr',
            head.encode('latin-1') + crop(blob, dims, bits // 8, 256))
        found.append(inr)
    nii = os.path.join(data, 'colin27.nii.gz')
    if os.path.exists(nii):
        blob = gzip.decompress(open(nii, 'rb').read())
        h = bytearray(blob[:348])
        dims = struct.unpack_from('<3h', h, 42)
        bitpix = struct.unpack_from('<h', h, 72)[0]
        offset = int(struct.unpack_from('<f', h, 108)[0])
        struct.pack_into('<3h', h, 42, *CROP)
        struct.pack_into('<f', h, 108, 352.0)
        body = bytes(h) + b'\0' * 4 + crop(blob, dims, bitpix // 8, offset)
        put(out, 'volume_nifti_gz', 'colin27-crop.nii.gz', gzip.compress(body, mtime=0))
        put(out, 'volume_nifti', 'colin27-crop.nii', body)
        found.append(nii)
    plt = os.path.join(data, 'nAChR_M2_water.plt')
    if os.path.exists(plt):
        blob = open(plt, 'rb').read()
        rank, kind, nz, ny, nx = struct.unpack_from('<5i', blob, 0)
        ext = struct.unpack_from('<6f', blob, 20)
        scale = [CROP[2] / nz, CROP[1] / ny, CROP[0] / nx]
        new_ext = []
        for a in range(3):
            lo, hi = ext[2 * a], ext[2 * a + 1]
            new_ext += [lo, lo + (hi - lo) * scale[a]]
        body = struct.pack('<5i6f', rank, kind, CROP[2], CROP[1], CROP[0], *new_ext)
        put(out, 'volume_plt', 'water-crop.plt', body + crop(blob, (nx, ny, nz), 4, 44))
        found.append(plt)
    for path in sorted(glob.glob(os.path.join(data, '*.raw.json'))):
        put(out, 'volume_raw_sidecar', os.path.basename(path), open(path, 'rb').read())
        found.append(path)
    off = os.path.join(data, 'meshes', 'head.off')
    if os.path.exists(off):
        tokens = open(off).read().split('\n')
        lines = [t for t in tokens if t.strip() and not t.startswith('#')]
        nv, nf = (int(v) for v in lines[1].split()[:2])
        verts = lines[2:2 + nv]
        faces = [list(map(int, f.split()))[1:4] for f in lines[2 + nv:2 + nv + 200]]
        used = sorted({i for f in faces for i in f})
        index = {v: n for n, v in enumerate(used)}
        text = 'OFF\n%d %d 0\n' % (len(used), len(faces)) + ''.join(verts[i] + '\n' for i in used) + \
            ''.join('3 %d %d %d\n' % tuple(index[i] for i in f) for f in faces)
        put(out, 'mesh_off', 'head-first-200-faces.off', text.encode())
        found.append(off)
    return found


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('out')
    ap.add_argument('--data', default=os.path.join(HERE, '..', '..', 'data'))
    args = ap.parse_args()
    scratch = os.path.join(args.out, '.scratch')
    os.makedirs(scratch, exist_ok=True)
    synthetic(args.out, scratch)
    shutil.rmtree(scratch)
    found = from_real_data(args.out, args.data) if os.path.isdir(args.data) else []
    print('seeds in %s; from real data: %s' % (args.out, ', '.join(map(os.path.basename, found))
                                               or 'none (run datasets-scripts/fetch_datasets.sh)'))


if __name__ == '__main__':
    main()
