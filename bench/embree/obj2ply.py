#!/usr/bin/env python3
import struct, sys
# A developer's tool for the PLY reader's speed figure: the torus of torus.awk as PLY.
# obj2ply.py IN.obj OUT.ply: v and f (triangles) lines of an OBJ as binary little-endian PLY
vs=[]; fs=[]
for line in open(sys.argv[1]):
    if line.startswith('v '):
        vs.append(tuple(map(float,line.split()[1:4])))
    elif line.startswith('f '):
        fs.append(tuple(int(t.split('/')[0])-1 for t in line.split()[1:]))
with open(sys.argv[2],'wb') as o:
    o.write(("ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty float x\nproperty float y\nproperty float z\nelement face %d\nproperty list uchar int vertex_indices\nend_header\n"%(len(vs),len(fs))).encode())
    o.write(b''.join(struct.pack('<fff',*v) for v in vs))
    o.write(b''.join(struct.pack('<B%di'%len(f),len(f),*f) for f in fs))
