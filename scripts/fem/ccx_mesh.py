"""What the scripts that mesh APA95ML.step for CalculiX share (scripts/fixtures/make_fem_fixtures.sh,
scripts/bench/make_cb_mesh.sh): gmsh's Abaqus .inp read into metres, and the remote points: a
REF node and a ROT node at the centre of a set of face nodes, tied to them by *RIGID BODY (the
ROT node's translations are the rotations)."""


def read_gmsh_inp(path, element_type):
    """Nodes {id: [x, y, z]} in m (gmsh writes mm) and the blocks of one element type
    {ELSET: [[element id, node ids...]]}, in file order."""
    nodes, blocks, mode, cur = {}, {}, None, None
    for line in open(path):
        s = line.strip()
        if s.startswith('*'):
            u = s.upper().replace(' ', '')
            if u.startswith('*NODE'):
                mode = 'node'
            elif u.startswith('*ELEMENT') and 'TYPE=' + element_type in u:
                mode, cur = 'elem', u.split('ELSET=')[1]
                blocks[cur] = []
            else:
                mode = None
            continue
        if not s:
            continue
        if mode == 'node':
            p = s.split(',')
            nodes[int(p[0])] = [float(v) * 1e-3 for v in p[1:4]]  # mm -> m
        elif mode == 'elem':
            blocks[cur].append([int(v) for v in s.split(',') if v.strip()])
    return nodes, blocks


def used_nodes(blocks):
    """The nodes the elements use, sorted (gmsh also writes the geometry's other points)."""
    return sorted({n for es in blocks.values() for e in es for n in e[1:]})


def write_nodes(f, nodes, used):
    """*NODE, NSET=NALL with 12 significant digits (ccx reads fields of at most 20 characters)."""
    f.write('*NODE, NSET=NALL\n')
    for n in used:
        f.write('%d, %.12g, %.12g, %.12g\n' % (n, *nodes[n]))


def write_remote_points(f, nodes, faces, first_id):
    """An *NSET per face and the *NODE, NSET=REMOTE block of their REF and ROT nodes (ids from
    first_id on, at the face's centroid). Returns {face: (ref, rot, centre)}."""
    refs = {}
    for k, (name, ids) in enumerate(faces.items()):
        assert len(ids) >= 3, (name, len(ids))
        f.write('*NSET, NSET=%s\n' % name)
        for i in range(0, len(ids), 10):
            f.write(', '.join(map(str, ids[i:i + 10])) + '\n')
        c = [sum(nodes[n][d] for n in ids) / len(ids) for d in range(3)]
        refs[name] = (first_id + 2 * k, first_id + 1 + 2 * k, c)
    f.write('** remote points: REF NODE (translations) and ROT NODE (its translations are the rotations)\n'
            '*NODE, NSET=REMOTE\n')
    for name, (ref, rot, c) in refs.items():
        f.write('%d, %.12g, %.12g, %.12g\n' % (ref, *c))
        f.write('%d, %.12g, %.12g, %.12g\n' % (rot, *c))
    return refs


def rigid_bodies(refs):
    """The *RIGID BODY lines that tie each face to its remote point."""
    return ['*RIGID BODY, NSET=%s, REF NODE=%d, ROT NODE=%d' % (name, ref, rot) for name, (ref, rot, _) in refs.items()]
