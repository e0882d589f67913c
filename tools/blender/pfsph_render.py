# Render a pfsph run directory in Blender's background mode: PNG frames and an mp4 (ffmpeg).
#   blender -b -P tools/blender/pfsph_render.py -- RUN_DIR OUT_DIR [--size WxH] [--samples N]
#                                                  [--frames A:B] [--engine CYCLES|BLENDER_EEVEE]
# The scene's camera (scene.json "camera", else one framing the domain), a sun and a sky-grey world,
# water (glass-like), foam (white) and solids (grey). Cycles on the CPU by default: it needs no
# display, so it works on a headless machine. docs/artists.md.
import json
import os
import shutil
import subprocess
import sys

import bpy
from mathutils import Vector

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import pfsph_load  # noqa: E402


def _z_up(p):
    return Vector((p[0], -p[2], p[1]))


def setup_camera(scene_json):
    cam = scene_json.get("camera", {})
    dmin = scene_json.get("domain", {}).get("min", [0, 0, 0]) + [0]
    dmax = scene_json.get("domain", {}).get("max", [1, 1, 1]) + [0]
    ext = max(dmax[k] - dmin[k] for k in range(3))
    target = cam.get("target", [(dmin[k] + dmax[k]) / 2 for k in range(3)])
    eye = cam.get("eye", [target[0] + 0.35 * ext, target[1] + 0.45 * ext, target[2] + 1.4 * ext])
    data = bpy.data.cameras.new("pfsph camera")
    data.angle_y = cam.get("fov", 40) * 3.14159265 / 180
    data.sensor_fit = "VERTICAL"
    ob = bpy.data.objects.new("pfsph camera", data)
    bpy.context.scene.collection.objects.link(ob)
    ob.location = _z_up(eye)
    direction = _z_up(target) - ob.location
    ob.rotation_euler = direction.to_track_quat("-Z", "Y").to_euler()
    bpy.context.scene.camera = ob
    return cam


def setup_lights():
    sun = bpy.data.lights.new("pfsph sun", "SUN")
    sun.energy = 3.0
    ob = bpy.data.objects.new("pfsph sun", sun)
    ob.rotation_euler = (0.7, 0.2, 0.6)
    bpy.context.scene.collection.objects.link(ob)
    world = bpy.data.worlds.new("pfsph world")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.6, 0.65, 0.7, 1.0)
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.8
    bpy.context.scene.world = world
    plane = bpy.data.meshes.new("pfsph floor")
    s = 50.0
    plane.from_pydata([(-s, -s, 0), (s, -s, 0), (s, s, 0), (-s, s, 0)], [], [(0, 1, 2, 3)])
    fl = bpy.data.objects.new("pfsph floor", plane)
    fl.location.z = -0.002
    fl.data.materials.append(pfsph_load._material("pfsph floor", (0.35, 0.35, 0.33), "solid"))
    bpy.context.scene.collection.objects.link(fl)


def main(argv):
    args = argv[argv.index("--") + 1:] if "--" in argv else []
    if len(args) < 2:
        print("usage: blender -b -P pfsph_render.py -- RUN_DIR OUT_DIR [--size WxH] [--samples N] "
              "[--frames A:B] [--engine CYCLES|BLENDER_EEVEE]")
        return 2
    run_dir, out_dir = args[0], os.path.abspath(args[1])
    opt = {args[i]: args[i + 1] for i in range(2, len(args) - 1, 2)}
    for o in bpy.data.objects:  # the factory scene's cube, light and camera
        bpy.data.objects.remove(o)
    report = pfsph_load.load_run(run_dir)
    with open(os.path.join(run_dir, "scene.json")) as f:
        scene_json = json.load(f)
    cam = setup_camera(scene_json)
    setup_lights()
    sc = bpy.context.scene
    sc.render.engine = opt.get("--engine", "CYCLES")
    if sc.render.engine == "CYCLES":
        sc.cycles.device = "CPU"
        sc.cycles.samples = int(opt.get("--samples", "32"))
        sc.cycles.use_denoising = False
    w, h = opt.get("--size", f"{cam.get('width', 640)}x{cam.get('height', 360)}").split("x")
    sc.render.resolution_x, sc.render.resolution_y = int(w), int(h)
    sc.render.resolution_percentage = 100
    sc.render.image_settings.file_format = "PNG"
    if "--frames" in opt:
        a, b = opt["--frames"].split(":")
        sc.frame_start, sc.frame_end = int(a), int(b)
    os.makedirs(out_dir, exist_ok=True)
    sc.render.filepath = os.path.join(out_dir, "frame_")
    bpy.ops.render.render(animation=True)
    pngs = sorted(n for n in os.listdir(out_dir) if n.startswith("frame_") and n.endswith(".png"))
    print(f"pfsph_render: {len(pngs)} PNG frames in {out_dir} ({report['objects']} objects)")
    ffmpeg = shutil.which("ffmpeg")
    if ffmpeg and len(pngs) > 1:
        first = int(pngs[0][6:-4])
        subprocess.run([ffmpeg, "-y", "-loglevel", "error", "-framerate", str(sc.render.fps), "-start_number",
                        str(first), "-i", os.path.join(out_dir, "frame_%04d.png"), "-pix_fmt", "yuv420p",
                        "-vf", "scale=trunc(iw/2)*2:trunc(ih/2)*2", os.path.join(out_dir, "frames.mp4")],
                       check=True)
        print(f"pfsph_render: {os.path.join(out_dir, 'frames.mp4')}")
    elif not ffmpeg:
        print("pfsph_render: ffmpeg not found, no mp4")
    return 0


if __name__ == "__main__":
    rc = main(sys.argv)
    if rc:
        sys.exit(rc)
