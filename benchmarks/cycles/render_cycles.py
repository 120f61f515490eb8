"""Blender script: render a glTF with Cycles on the CPU, as a benchmark peer of Penumbra.

blender -b --factory-startup -P render_cycles.py -- SCENE OUT.exr WIDTH HEIGHT SPP THREADS BACKGROUND
Denoising and adaptive sampling off, a fixed thread count, a constant world colour BACKGROUND
(radiance), the scene's camera, Cycles' default 1.5 px Blackman-Harris filter and 12 bounces.
Prints 'cycles_render_seconds S' (the render alone, without import)."""
import sys, time
import numpy
numpy.bool = bool  # Blender 3.4's glTF importer uses numpy.bool, gone from Debian's numpy
import bpy

scene_file, out, w, h, spp, threads, bg = sys.argv[sys.argv.index("--") + 1:]
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.import_scene.gltf(filepath=scene_file)
sc = bpy.context.scene
cams = [o for o in sc.objects if o.type == "CAMERA"]
sc.camera = [c for c in cams if c.name.startswith("bench")][0] if any(c.name.startswith("bench") for c in cams) else cams[0]
sc.render.engine = "CYCLES"
sc.cycles.device = "CPU"
sc.cycles.samples = int(spp)
sc.cycles.use_adaptive_sampling = False
sc.cycles.use_denoising = False
sc.cycles.max_bounces = 12
sc.cycles.seed = 0
sc.render.threads_mode = "FIXED"
sc.render.threads = int(threads)
sc.render.resolution_x, sc.render.resolution_y, sc.render.resolution_percentage = int(w), int(h), 100
sc.render.film_transparent = False
world = bpy.data.worlds.new("bench")
world.use_nodes = True
world.node_tree.nodes["Background"].inputs[0].default_value = (float(bg), float(bg), float(bg), 1)
sc.world = world
sc.render.image_settings.file_format = "OPEN_EXR"
sc.render.image_settings.color_depth = "32"
sc.render.filepath = out
t0 = time.time()
bpy.ops.render.render(write_still=True)
print("cycles_render_seconds %.3f" % (time.time() - t0))
