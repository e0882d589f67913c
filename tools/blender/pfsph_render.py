# Render a pfsph run directory in Blender's background mode: PNG frames and an mp4 (ffmpeg).
#   blender -b -P tools/blender/pfsph_render.py -- RUN_DIR OUT_DIR [--size WxH] [--samples N]
#                                                  [--frames A:B] [--engine CYCLES|BLENDER_EEVEE]
# The loader's stage (pfsph_load.setup_stage: the scene's camera, a sun, a sky-grey world, a floor),
# water (glass-like), foam (white) and solids (grey). Cycles on the CPU by default: it needs no
# display, so it works on a headless machine. docs/artists.md.
import json
import os
import shutil
import subprocess
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import pfsph_load  # noqa: E402


def main(argv):
    args = argv[argv.index("--") + 1:] if "--" in argv else []
    if len(args) < 2:
        print("usage: blender -b -P pfsph_render.py -- RUN_DIR OUT_DIR [--size WxH] [--samples N] "
              "[--frames A:B] [--engine CYCLES|BLENDER_EEVEE]")
        return 2
    run_dir, out_dir = args[0], os.path.abspath(args[1])
    opt = {args[i]: args[i + 1] for i in range(2, len(args) - 1, 2)}
    pfsph_load.clear_startup()
    report = pfsph_load.load_run(run_dir)
    with open(os.path.join(run_dir, "scene.json")) as f:
        scene_json = json.load(f)
    cam = pfsph_load.setup_stage(scene_json)
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
