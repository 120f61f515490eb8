"""Blender script: render a glTF with Cycles on the CPU, as a benchmark peer of Penumbra.

blender -b --factory-startup -P render_cycles.py -- SCENE OUT.exr WIDTH HEIGHT SPP THREADS BACKGROUND [KEY=VALUE ...]
Denoising and adaptive sampling off, a fixed thread count, a constant world colour BACKGROUND
(radiance), the scene's camera, Cycles' default 1.5 px Blackman-Harris filter and 12 bounces.
Prints 'cycles_render_seconds S' (the render alone, without import).

Optional KEY=VALUE settings (for cross-checks against Penumbra's flags of the same names):
  seed=N                     Cycles' sampling seed (default 0)
  look_at=EX,EY,EZ:TX,TY,TZ  a new camera at EYE looking at TARGET, given in glTF coordinates
                             (+Y up, as Penumbra's --look-at with its default up); the importer
                             turns glTF's +Y up into Blender's +Z up, (x, y, z) -> (x, -z, y)
  lens=MM sensor=MM          that camera's focal length and sensor width (default 50 and 36,
                             sensor fit Auto: the sensor spans the image's larger side)
  fstop=N focus=D            depth of field: the camera's f-number and focus distance
  blades=N rotation=DEG ratio=A   the aperture's blades, their rotation and anamorphic ratio
  transparent=1              film transparent: alpha is the camera rays' coverage
  filter=box|gaussian|blackman-harris filter_width=PX   the pixel filter
  bounces=N                  maximum bounces (default 12)"""
import math, sys, time
import numpy
numpy.bool = bool  # Blender 3.4's glTF importer uses numpy.bool, gone from Debian's numpy
import bpy
from mathutils import Vector

args = sys.argv[sys.argv.index("--") + 1:]
scene_file, out, w, h, spp, threads, bg = args[:7]
opt = dict(a.split("=", 1) for a in args[7:])
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.import_scene.gltf(filepath=scene_file)
sc = bpy.context.scene
if "look_at" in opt:
    eye, target = ([float(v) for v in p.split(",")] for p in opt["look_at"].split(":"))
    to_blender = lambda p: Vector((p[0], -p[2], p[1]))
    cam = bpy.data.objects.new("look_at", bpy.data.cameras.new("look_at"))
    sc.collection.objects.link(cam)
    cam.location = to_blender(eye)
    # The camera looks down its -Z with its +Y towards world +Z (glTF's +Y).
    cam.rotation_euler = (to_blender(target) - to_blender(eye)).to_track_quat("-Z", "Y").to_euler()
    cam.data.sensor_fit = "AUTO"
    cam.data.sensor_width = float(opt.get("sensor", 36))
    cam.data.lens = float(opt.get("lens", 50))
    cam.data.clip_start = 1e-4
    sc.camera = cam
else:
    cams = [o for o in sc.objects if o.type == "CAMERA"]
    sc.camera = [c for c in cams if c.name.startswith("bench")][0] if any(c.name.startswith("bench") for c in cams) else cams[0]
if "fstop" in opt:
    dof = sc.camera.data.dof
    dof.use_dof = True
    dof.aperture_fstop = float(opt["fstop"])
    dof.focus_distance = float(opt["focus"])
    dof.aperture_blades = int(opt.get("blades", 0))
    dof.aperture_rotation = math.radians(float(opt.get("rotation", 0)))
    dof.aperture_ratio = float(opt.get("ratio", 1))
sc.render.engine = "CYCLES"
sc.cycles.device = "CPU"
sc.cycles.samples = int(spp)
sc.cycles.use_adaptive_sampling = False
sc.cycles.use_denoising = False
sc.cycles.max_bounces = int(opt.get("bounces", 12))
sc.cycles.seed = int(opt.get("seed", 0))
if "filter" in opt:
    sc.cycles.pixel_filter_type = {"box": "BOX", "gaussian": "GAUSSIAN", "blackman-harris": "BLACKMAN_HARRIS"}[opt["filter"]]
if "filter_width" in opt:
    sc.cycles.filter_width = float(opt["filter_width"])
sc.render.threads_mode = "FIXED"
sc.render.threads = int(threads)
sc.render.resolution_x, sc.render.resolution_y, sc.render.resolution_percentage = int(w), int(h), 100
sc.render.film_transparent = opt.get("transparent", "0") == "1"
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
