# Run by compositor_test.sh inside Blender (blender -b --factory-startup --python THIS -- EXR):
# loads a Penumbra EXR into the compositor's Image node and prints one "PASS <name> <type>" line
# per output socket, as a compositor artist would see them.
import sys

import bpy

path = sys.argv[sys.argv.index("--") + 1]
image = bpy.data.images.load(path)
tree = bpy.context.scene
tree.use_nodes = True
node = tree.node_tree.nodes.new("CompositorNodeImage")
node.image = image
for socket in node.outputs:
    print("PASS", socket.name, socket.type)
