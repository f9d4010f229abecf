#!/usr/bin/python3
"""Extract the boundary quad surface of a gmsh all-hex mesh -> OBJ (outward oriented).
Usage: gmsh_boundary.py IN.msh OUT.obj [VOLUME_TOLERANCE]
prints a one-line JSON summary; exit 1 if rejected. The surface's volume must match the hexes'
within VOLUME_TOLERANCE relative (default 1e-6; curved shapes with non-planar quads need ~1e-2)."""
import sys, json
import numpy as np, meshio
HF = np.array([(0,3,2,1),(4,5,6,7),(0,1,5,4),(1,2,6,5),(2,3,7,6),(3,0,4,7)])
def hexvol(P, H):
    # volume via 5-tet / decomposition into 6 tets sharing diagonal 0-6
    p = P[H]
    tets = [(0,1,2,6),(0,2,3,6),(0,3,7,6),(0,7,4,6),(0,4,5,6),(0,5,1,6)]
    v = 0
    for a,b,c,d in tets:
        v = v + np.einsum('ij,ij->i', p[:,b]-p[:,a], np.cross(p[:,c]-p[:,a], p[:,d]-p[:,a]))/6
    return v
def main(inp, out, tol=1e-6):
    m = meshio.read(inp)
    types = {}
    H = []
    for cb in m.cells:
        types[cb.type] = types.get(cb.type, 0) + len(cb.data)
        if cb.type == "hexahedron": H.append(cb.data)
    vol3 = {t: n for t, n in types.items() if t in ("tetra","wedge","pyramid","hexahedron")}
    info = {"msh": inp, "cell_types": vol3}
    H = np.vstack(H).astype(np.int64)
    P = m.points.astype(float)
    v = hexvol(P, H)
    info["hexes"] = int(len(H)); info["neg_hex"] = int((v <= 0).sum()); info["pos_hex"] = int((v > 0).sum())
    if (v <= 0).all():
        H = H[:, [0,3,2,1,4,7,6,5]]; info["flipped_hexes"] = True
    elif (v <= 0).any():
        info["reject"] = "mixed hex orientation"
        print(json.dumps(info)); return 1
    if set(vol3) != {"hexahedron"}:
        info["reject"] = "non-hex volume cells"; print(json.dumps(info)); return 1
    faces = H[:, HF].reshape(-1, 4)
    key = np.sort(faces, axis=1)
    _, inv, cnt = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    inv = inv.ravel()
    B = faces[cnt[inv] == 1]
    info["face_mult_max"] = int(cnt.max())
    used = np.unique(B)
    ren = -np.ones(len(P), dtype=np.int64); ren[used] = np.arange(len(used))
    V = P[used]; F = ren[B]
    # signed volume of closed surface (quads split in 2 tris)
    def sv(F):
        a, b, c, d = (V[F[:,i]] for i in range(4))
        return (np.einsum('ij,ij->i', a, np.cross(b, c)) + np.einsum('ij,ij->i', a, np.cross(c, d))).sum()/6
    s = sv(F)
    if s < 0: F = F[:, ::-1]; s = -s; info["reversed_faces"] = True
    info["surface_volume"] = float(s); info["hex_volume"] = float(abs(v).sum())
    # edges
    E = np.concatenate([F[:, [i, (i+1)%4]] for i in range(4)])
    Es = np.sort(E, axis=1)
    ue, ec = np.unique(Es, axis=0, return_counts=True)
    # directed edges each appear once (consistent orientation)
    ud, dc = np.unique(E, axis=0, return_counts=True)
    nV, nE, nF = len(V), len(ue), len(F)
    info.update(V=nV, E=nE, F=nF, euler=nV-nE+nF, edge_mult=sorted(set(ec.tolist())),
                oriented=bool(dc.max() == 1))
    # duplicate coincident points?
    info["dup_points"] = int(len(V) - len(np.unique(np.round(V, 9), axis=0)))
    ok = info["euler"] == 2 and info["edge_mult"] == [2] and info["oriented"] and info["dup_points"] == 0 \
         and abs(info["surface_volume"] - info["hex_volume"]) < tol * max(1, info["hex_volume"])
    if not ok:
        info["reject"] = "topology/volume check failed"; print(json.dumps(info)); return 1
    with open(out, "w") as f:
        f.write(f"# boundary of {inp}: {nV} vertices, {nF} quads\n")
        for p in V: f.write(f"v {p[0]:.17g} {p[1]:.17g} {p[2]:.17g}\n")
        for q in F + 1: f.write(f"f {q[0]} {q[1]} {q[2]} {q[3]}\n")
    print(json.dumps(info)); return 0
sys.exit(main(sys.argv[1], sys.argv[2], *(float(a) for a in sys.argv[3:4])))
