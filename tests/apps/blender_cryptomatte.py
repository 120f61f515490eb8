# Run by compositor_test.sh inside Blender
# (blender -b --factory-startup --python THIS -- EXR LAYER NAME OUT.exr WIDTH HEIGHT):
# picks NAME's matte from the Cryptomatte layer LAYER of a Penumbra EXR with Blender's own
# Cryptomatte node (source: image) and writes the matte through the compositor to OUT.exr.
import sys

import bpy

path, layer, name, out, width, height = sys.argv[sys.argv.index("--") + 1:]
image = bpy.data.images.load(path)
scene = bpy.context.scene
scene.use_nodes = True
tree = scene.node_tree
for n in list(tree.nodes):
    tree.nodes.remove(n)
crypto = tree.nodes.new("CompositorNodeCryptomatteV2")
crypto.source = "IMAGE"
crypto.image = image
layers = [item.identifier for item in crypto.bl_rna.properties["layer_name"].enum_items]
print("LAYERS", ",".join(layers))
if layer not in layers:
    sys.exit("no Cryptomatte layer " + layer)
crypto.layer_name = layer
crypto.matte_id = name
composite = tree.nodes.new("CompositorNodeComposite")
tree.links.new(crypto.outputs["Matte"], composite.inputs["Image"])
scene.render.resolution_x = int(width)
scene.render.resolution_y = int(height)
scene.render.resolution_percentage = 100
scene.render.engine = "BLENDER_WORKBENCH"
scene.render.image_settings.file_format = "OPEN_EXR"
scene.render.image_settings.color_depth = "32"
scene.render.filepath = out
bpy.ops.render.render(write_still=True)
