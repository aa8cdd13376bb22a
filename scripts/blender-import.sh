#!/usr/bin/env bash
# Imports every given .glb or .obj into Blender headless (Debian's `blender` and `python3-numpy`
# packages; not installed by scripts/setup.sh, see docs/export.md) and checks that every mesh node of the file became a
# Blender object with the triangles the file holds: every LOD, the billboard, the sketch extras.
# Prints one line per file and exits 1 when an import fails or a mesh is missing or differs.
# For an .obj, also that the leaf, bark and billboard materials take their base colour from
# their PNG (the colours are baked in).
#   scripts/blender-import.sh tree.glb [more.glb tree.obj …]
set -euo pipefail
if ! command -v blender >/dev/null; then
  echo "blender-import: blender is not installed (apt-get install --no-install-recommends blender python3-numpy)" >&2
  exit 2
fi
status=0
for glb in "$@"; do
  if ! out="$(blender -b --factory-startup --python-exit-code 3 --python-expr "
import bpy, json, struct, sys
import numpy
# Blender 3.4's glTF importer uses numpy.bool, which Debian 12's numpy 1.24 no longer has.
if not hasattr(numpy, 'bool') or 'bool' in getattr(numpy, '__former_attrs__', {}): numpy.bool = bool
path = sys.argv[sys.argv.index('--') + 1]
expected = {}
bpy.ops.wm.read_factory_settings(use_empty=True)
if path.lower().endswith('.obj'):
    name = None
    for line in open(path):
        if line.startswith('o '): name = line[2:].strip(); expected[name] = 0
        elif line.startswith('f ') and name: expected[name] += 1
    bpy.ops.wm.obj_import(filepath=path, forward_axis='NEGATIVE_Z', up_axis='Y')
    # The colour comes from the textures: the leaf and bark materials' base colour is an
    # image that was found, and white Kd leaves it as it is.
    for mat in bpy.data.materials:
        if mat.name.split('.')[0] not in ('leaf', 'bark', 'billboard') or not mat.use_nodes: continue
        bsdf = next((n for n in mat.node_tree.nodes if n.type == 'BSDF_PRINCIPLED'), None)
        links = bsdf.inputs['Base Color'].links if bsdf else []
        image = links[0].from_node.image if links and links[0].from_node.type == 'TEX_IMAGE' else None
        if image is None or image.size[0] == 0:
            print('BLENDER-IMPORT', mat.name, 'has no base colour texture'); sys.exit(3)
        print('BLENDER-IMPORT', mat.name, 'base colour from', image.name, tuple(image.size))
else:
    data = open(path, 'rb').read()
    length = struct.unpack('<I', data[12:16])[0]
    gltf = json.loads(data[20:20 + length])
    for node in gltf.get('nodes', []):
        if 'mesh' not in node: continue
        tris = 0
        for prim in gltf['meshes'][node['mesh']]['primitives']:
            if prim.get('mode', 4) == 4: tris += gltf['accessors'][prim['indices']]['count'] // 3
        expected[node['name']] = tris
    bpy.ops.import_scene.gltf(filepath=path)
got = {}
for obj in bpy.data.objects:
    if obj.type != 'MESH': continue
    mesh = obj.data
    mesh.calc_loop_triangles()
    got[obj.name] = len(mesh.loop_triangles)
bad = [f'{n}: {t} triangles in the file, {got.get(n)} in Blender' for n, t in expected.items() if t and got.get(n) != t]
missing = [n for n, t in expected.items() if n not in got]
print('BLENDER-IMPORT', len(expected), 'meshes,', sum(got.values()), 'triangles;', 'bad:', bad, 'missing:', missing)
sys.exit(3 if bad or missing else 0)
" -- "$glb" 2>&1)"; then
    echo "blender-import: $glb: FAILED"
    echo "$out" | grep -E "BLENDER-IMPORT|Error|error" | head -5
    status=1
  else
    echo "$out" | grep BLENDER-IMPORT | sed "s|^BLENDER-IMPORT |blender-import: $glb: |"
  fi
done
exit $status
