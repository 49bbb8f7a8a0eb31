#!/usr/bin/env python3
"""Mutation fuzzing of visopt's readers from the command line (issue 13; a stand-in until the
libFuzzer targets exist): small valid seeds of every volume header format, a session and four
mesh formats are mutated (byte flips, numeric tokens such as nan, 1e30 and 2147483647, cuts) and
fed to `visopt info`/`render`, `render --session`/`session-info` and `visopt sdf` under an
address-space cap. Exit codes 0-3 are answers; anything else (a signal) or a timeout is a
finding, copied to OUT/findings. Prints the count of each (seed, command, outcome).

  python3 tests/fuzz/mutate_inputs.py volumes|sessions|meshes --visopt build/bin/visopt \
      [--count 1000] [--seed 1] [--out /tmp/visopt-fuzz] [--session FILE]
"""
import argparse, array, json, os, random, shutil, struct, subprocess

TOKENS = [b'0', b'-1', b'1e30', b'-3e38', b'nan', b'inf', b'65536', b'2147483647',
          b'99999999999', b'1e-30', b'', b' ', b'\n']


def volume_seeds(d, dims=(16, 16, 8)):
    nx, ny, nz = dims
    vals = array.array('h', (i % 3000 for i in range(nx * ny * nz)))
    raw = vals.tobytes()
    h = bytearray(348)
    struct.pack_into('<i', h, 0, 348)
    struct.pack_into('<8h', h, 40, 3, nx, ny, nz, 1, 1, 1, 1)
    struct.pack_into('<2h', h, 70, 4, 16)
    struct.pack_into('<8f', h, 76, 1, 1, 1, 2, 1, 1, 1, 1)
    struct.pack_into('<2f', h, 108, 352.0, 1.0)
    struct.pack_into('<h', h, 254, 1)
    for r, row in enumerate(((1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 2, 0))):
        struct.pack_into('<4f', h, 280 + 16 * r, *row)
    h[344:348] = b'n+1\0'
    seeds = {
        'a.nii': bytes(h) + b'\0' * 4 + raw,
        'a.mha': b'ObjectType = Image\nNDims = 3\nDimSize = %d %d %d\nElementSpacing = 1 1 2\n'
                 b'ElementType = MET_SHORT\nElementDataFile = LOCAL\n' % dims + raw,
        'a.nrrd': b'NRRD0004\ntype: short\ndimension: 3\nsizes: %d %d %d\nspacings: 1 1 2\n'
                  b'encoding: raw\nendian: little\n\n' % dims + raw,
    }
    be = array.array('h', vals)
    be.byteswap()
    seeds['a.vtk'] = (b'# vtk DataFile Version 3.0\nx\nBINARY\nDATASET STRUCTURED_POINTS\n'
                      b'DIMENSIONS %d %d %d\nORIGIN 0 0 0\nSPACING 1 1 2\nPOINT_DATA %d\n'
                      b'SCALARS s short 1\nLOOKUP_TABLE default\n' % (dims + (nx * ny * nz,)) +
                      be.tobytes() + b'\n')
    inr = (b'#INRIMAGE-4#{\nXDIM=%d\nYDIM=%d\nZDIM=%d\nVDIM=1\nTYPE=signed fixed\n'
           b'PIXSIZE=16 bits\nCPU=decm\nVX=1\nVY=1\nVZ=2\n' % dims)
    seeds['a.inr'] = inr + b'\n' * (252 - len(inr)) + b'##}\n' + raw
    text = ' '.join(str(v) for v in vals)
    seeds['a.vti'] = ('<?xml version="1.0"?>\n<VTKFile type="ImageData" version="0.1" '
                      'byte_order="LittleEndian">\n<ImageData WholeExtent="0 %d 0 %d 0 %d" '
                      'Origin="0 0 0" Spacing="1 1 2">\n<Piece Extent="0 %d 0 %d 0 %d">\n'
                      '<PointData Scalars="s">\n<DataArray type="Int16" Name="s" format="ascii">\n'
                      % ((nx - 1, ny - 1, nz - 1) * 2) + text + '\n</DataArray>\n</PointData>\n</Piece>\n</ImageData>\n</VTKFile>\n'
                      ).encode()
    for name, data in seeds.items():
        open(os.path.join(d, name), 'wb').write(data)


def mesh_seeds(d):
    v = [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)]
    f = [(0, 2, 4), (2, 1, 4), (1, 3, 4), (3, 0, 4), (2, 0, 5), (1, 2, 5), (3, 1, 5), (0, 3, 5)]
    pts = ''.join('%g %g %g\n' % p for p in v)
    tri = ''.join('3 %d %d %d\n' % t for t in f)
    files = {
        'a.off': 'OFF\n%d %d 0\n' % (len(v), len(f)) + pts + tri,
        'a.obj': ''.join('v ' + '%g %g %g\n' % p for p in v) +
                 ''.join('f %d %d %d\n' % (a + 1, b + 1, c + 1) for a, b, c in f),
        'a.ply': 'ply\nformat ascii 1.0\nelement vertex 6\nproperty float x\nproperty float y\n'
                 'property float z\nelement face 8\nproperty list uchar int vertex_indices\n'
                 'end_header\n' + pts + tri,
        'a.stl': 'solid a\n' + ''.join(
            'facet normal 0 0 0\nouter loop\n' + ''.join('vertex %g %g %g\n' % v[i] for i in t) +
            'endloop\nendfacet\n' for t in f) + 'endsolid a\n',
    }
    for name, text in files.items():
        open(os.path.join(d, name), 'w').write(text)


def mutate_bytes(data, reach):
    data = bytearray(data)
    for _ in range(random.randint(1, 4)):
        op, p = random.random(), random.randrange(min(reach, len(data)))
        if op < 0.4:
            data[p] = random.randrange(256)
        elif op < 0.7:
            q = p
            while q < len(data) and q < p + 12 and chr(data[q]).isdigit():
                q += 1
            data[p:max(q, p + 1)] = random.choice(TOKENS)
        elif op < 0.85:
            data = data[:random.randrange(len(data))] or bytearray(b'x')
        else:
            data[p:p + 4] = random.choice([b'\xff\xff\xff\x7f', b'\x00\x00\x80\x7f',
                                           b'\x00\x00\xc0\xff', b'\xff\xff\xff\xff', b'\0\0\0\0'])
    return bytes(data)


def mutate_session(doc):
    values = [float('nan'), float('inf'), -1, 0, 1e30, -1e30, 1e-30, 2 ** 31, 2 ** 63, 'x', None,
              [], {}, True, 65536, 1e6, 4096]
    paths = []

    def walk(o, path):
        if isinstance(o, dict):
            for k, v in o.items():
                walk(v, path + (k,))
        elif isinstance(o, list):
            for i, v in enumerate(o):
                walk(v, path + (i,))
        else:
            paths.append(path)
    walk(doc, ())
    doc = json.loads(json.dumps(doc))
    for _ in range(random.randint(1, 3)):
        path = random.choice(paths)
        o = doc
        for p in path[:-1]:
            o = o[p]
        o[path[-1]] = random.choice(values)
    return json.dumps(doc).replace('Infinity', '1e999').encode()


def main():
    a = argparse.ArgumentParser()
    a.add_argument('target', choices=['volumes', 'sessions', 'meshes'])
    a.add_argument('--visopt', required=True)
    a.add_argument('--count', type=int, default=1000)
    a.add_argument('--seed', type=int, default=1)
    a.add_argument('--out', default='/tmp/visopt-fuzz')
    a.add_argument('--session', help='a saved session to mutate (sessions target)')
    a.add_argument('--timeout', type=float, default=20.0)
    args = a.parse_args()
    random.seed(args.seed)
    seeds_dir, work, findings = (os.path.join(args.out, n) for n in ('seeds', 'work', 'findings'))
    for d in (seeds_dir, work, findings):
        os.makedirs(d, exist_ok=True)
    if args.target == 'volumes':
        volume_seeds(seeds_dir)
    elif args.target == 'meshes':
        mesh_seeds(seeds_dir)
    else:
        if not args.session:
            a.error('the sessions target needs --session FILE')
        shutil.copy(args.session, os.path.join(seeds_dir, 'a.visopt-session'))
    seeds = sorted(os.listdir(seeds_dir))
    counts = {}
    for n in range(args.count):
        seed = random.choice(seeds)
        data = open(os.path.join(seeds_dir, seed), 'rb').read()
        ext = os.path.splitext(seed)[1]
        if args.target == 'sessions':
            data = mutate_session(json.loads(data))
        else:
            data = mutate_bytes(data, 400 if args.target == 'volumes' else len(data))
        path = os.path.join(work, 'm' + ext)
        open(path, 'wb').write(data)
        if args.target == 'volumes':
            cmds = [['info', path], ['render', '--volume', path, '--size', '24x24', '--out',
                                     os.path.join(work, 'o.png')]]
        elif args.target == 'sessions':
            cmds = [['session-info', path], ['render', '--session', path, '--size', '24x24',
                                             '--out', os.path.join(work, 'o.png')]]
        else:
            cmds = [['sdf', '--mesh', path, '--filled', '--voxel', '0.1', '--out',
                     os.path.join(work, 'o.vdb')]]
        for cmd in cmds:
            try:
                r = subprocess.run(['bash', '-c', 'ulimit -v 4000000; exec "$@"', 'visopt',
                                    args.visopt] + cmd, capture_output=True, timeout=args.timeout)
                outcome = r.returncode if r.returncode in (0, 1, 2, 3) else 'signal %d' % -r.returncode
            except subprocess.TimeoutExpired:
                outcome = 'timeout'
            key = (seed, cmd[0], str(outcome))
            counts[key] = counts.get(key, 0) + 1
            if not isinstance(outcome, int):
                kept = os.path.join(findings, '%s-%s-%d%s' % (cmd[0], outcome.replace(' ', ''), n, ext))
                shutil.copy(path, kept)
                print('finding:', kept, flush=True)
            if outcome != 0:
                break
    for key in sorted(counts):
        print('%-22s %-13s %-10s %d' % (key + (counts[key],)))


if __name__ == '__main__':
    main()
