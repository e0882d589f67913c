# Load a pfsph run directory into Blender as an animated scene (Blender 3.4 and later):
#   blender -b -P tools/blender/pfsph_load.py -- RUN_DIR [--save out.blend] [--report report.json]
# or, inside Blender's Python console: import pfsph_load; pfsph_load.load_run("/path/to/run").
# The liquid is the mesh sequence frames/liquid_NNNNN.ply (`pfsph mesh`, output.surface) or, without
# meshes, the fluid particles as a point cloud with their fields as attributes; diffuse particles one
# point cloud per type (spray, foam, bubble); rigid bodies one object each, their frame-0 surface
# moved by the poses of bodies.csv. pfsph is y-up, Blender z-up: positions turn (x, y, z) -> (x, -z, y).
# One object per frame and set, shown only on its frame (keyed visibility), so a saved .blend plays
# without add-ons. docs/artists.md.
import csv
import json
import math
import os
import sys

import bpy
import numpy as np
from mathutils import Vector

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import pfsph_io  # noqa: E402

DIFFUSE_TYPES = ("spray", "foam", "bubble")


def _collection(name, parent=None):
    c = bpy.data.collections.new(name)
    (parent or bpy.context.scene.collection).children.link(c)
    return c


def _mesh_object(name, verts, faces, coll):
    me = bpy.data.meshes.new(name)
    verts = np.asarray(verts, dtype=np.float32)
    me.vertices.add(len(verts))
    me.vertices.foreach_set("co", verts.ravel())
    if faces is not None and len(faces):
        faces = np.asarray(faces, dtype=np.int32)
        me.loops.add(faces.size)
        me.loops.foreach_set("vertex_index", faces.ravel())
        me.polygons.add(len(faces))
        me.polygons.foreach_set("loop_start", np.arange(0, faces.size, 3, dtype=np.int32))
        me.polygons.foreach_set("loop_total", np.full(len(faces), 3, dtype=np.int32))
        me.polygons.foreach_set("use_smooth", np.ones(len(faces), dtype=bool))
    me.update()
    me.validate()
    ob = bpy.data.objects.new(name, me)
    coll.objects.link(ob)
    return ob


def _add_point_attributes(me, fields):
    for k, a in fields.items():
        a = np.asarray(a)
        if a.ndim == 1 and a.dtype.kind in "iu":  # phase, type, id: integers
            at = me.attributes.new(k, "INT", "POINT")
            at.data.foreach_set("value", a.astype(np.int32))
        elif a.ndim == 1:
            at = me.attributes.new(k, "FLOAT", "POINT")
            at.data.foreach_set("value", a.astype(np.float32))
        elif a.ndim == 2 and a.shape[1] == 3:
            at = me.attributes.new(k, "FLOAT_VECTOR", "POINT")
            at.data.foreach_set("vector", pfsph_io.y_up_to_z_up(a).astype(np.float32).ravel())


def _show_only_on(ob, frame, first, last):
    """Keyed visibility: shown on `frame` only (constant interpolation)."""
    keys = [(frame, False)]
    if frame > first:
        keys.append((frame - 1, True))
    if frame < last:
        keys.append((frame + 1, True))
    for f, hide in keys:
        ob.hide_viewport = hide
        ob.hide_render = hide
        ob.keyframe_insert("hide_viewport", frame=f)
        ob.keyframe_insert("hide_render", frame=f)
    for fc in ob.animation_data.action.fcurves:
        for kp in fc.keyframe_points:
            kp.interpolation = "CONSTANT"


def _point_template(name, radius, coll):
    """A small sphere instanced on every vertex of a point cloud (renders in every engine)."""
    me = bpy.data.meshes.new(name)
    import bmesh
    bm = bmesh.new()
    bmesh.ops.create_icosphere(bm, subdivisions=1, radius=radius)
    bm.to_mesh(me)
    bm.free()
    ob = bpy.data.objects.new(name, me)
    coll.objects.link(ob)
    ob.hide_render = False
    return ob


def _material(name, color, kind):
    m = bpy.data.materials.get(name) or bpy.data.materials.new(name)
    m.use_nodes = True
    bsdf = m.node_tree.nodes.get("Principled BSDF")
    bsdf.inputs["Base Color"].default_value = (*color, 1.0)
    bsdf.inputs["Roughness"].default_value = 0.05 if kind == "water" else 0.02 if kind == "glass" else 0.6
    if kind in ("water", "glass"):
        key = "Transmission" if "Transmission" in bsdf.inputs else "Transmission Weight"
        bsdf.inputs[key].default_value = 1.0
        bsdf.inputs["IOR"].default_value = 1.33 if kind == "water" else 1.0  # thin glass: no lensing
    m.diffuse_color = (*color, 1.0)
    return m


def _quat_y_to_z(q):
    """A rotation (w, x, y, z) in pfsph's y-up frame as the same rotation in Blender's z-up frame:
    c q c^-1 with c the quarter turn about x that maps y-up onto z-up."""
    s = math.sqrt(0.5)
    c = (s, s, 0.0, 0.0)
    ci = (s, -s, 0.0, 0.0)

    def mul(a, b):
        return (a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
                a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
                a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
                a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0])
    return mul(mul(c, q), ci)


def _quat_rotate_inv(q, v):
    """R(q)^T v for unit q = (w, x, y, z), v (n, 3)."""
    w, x, y, z = q
    R = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                  [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                  [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
    return v @ R  # row vectors: (R^T v^T)^T = v R


def clear_startup():
    """Remove every object of the startup scene (Blender's default cube, camera and light): the
    command line loads into a fresh file, where they would show instead of the water. Not called
    by load_run, which adds to whatever scene is open."""
    for o in list(bpy.data.objects):
        bpy.data.objects.remove(o)
    for m in list(bpy.data.meshes):
        if not m.users:
            bpy.data.meshes.remove(m)


def _z_up(p):
    return Vector((p[0], -p[2], p[1]))


def setup_camera(scene_json):
    """The scene's camera (scene.json "camera"), else one framing the domain as `pfsph render` does."""
    cam = scene_json.get("camera", {})
    dmin = scene_json.get("domain", {}).get("min", [0, 0, 0]) + [0]
    dmax = scene_json.get("domain", {}).get("max", [1, 1, 1]) + [0]
    ext = max(dmax[k] - dmin[k] for k in range(3))
    target = cam.get("target", [(dmin[k] + dmax[k]) / 2 for k in range(3)])
    eye = cam.get("eye", [target[0] + 0.35 * ext, target[1] + 0.45 * ext, target[2] + 1.4 * ext])
    data = bpy.data.cameras.new("pfsph camera")
    data.angle_y = cam.get("fov", 40) * math.pi / 180
    data.sensor_fit = "VERTICAL"
    ob = bpy.data.objects.new("pfsph camera", data)
    bpy.context.scene.collection.objects.link(ob)
    ob.location = _z_up(eye)
    direction = _z_up(target) - ob.location
    ob.rotation_euler = direction.to_track_quat("-Z", "Y").to_euler()
    bpy.context.scene.camera = ob
    sc = bpy.context.scene
    sc.render.resolution_x, sc.render.resolution_y = int(cam.get("width", 640)), int(cam.get("height", 360))
    return cam


def setup_lights():
    """A sun, a sky-grey world and a floor just below y = 0."""
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
    fl.data.materials.append(_material("pfsph floor", (0.35, 0.35, 0.33), "solid"))
    bpy.context.scene.collection.objects.link(fl)


def setup_stage(scene_json):
    """Camera, sun, world and floor, so that a saved .blend renders the run as pfsph_render does."""
    cam = setup_camera(scene_json)
    setup_lights()
    return cam


def load_run(run_dir, max_frames=None):
    """Build the scene; returns a report dict (objects, frame range, faces per liquid frame)."""
    run_dir = os.path.abspath(run_dir)
    with open(os.path.join(run_dir, "scene.json")) as f:
        scene_json = json.load(f)
    radius = float(scene_json.get("particle_radius", 0.01))
    fps = float(scene_json.get("time", {}).get("fps", 25))
    interval = int(scene_json.get("output", {}).get("frame_interval", 1))
    sc = bpy.context.scene
    root = _collection("pfsph " + os.path.basename(run_dir))
    report = {"objects": 0, "liquid_faces": {}, "sets": {}}
    water = _material("pfsph water", (0.55, 0.75, 0.95), "water")
    foam = _material("pfsph foam", (0.95, 0.95, 0.95), "foam")
    solid = _material("pfsph solid", (0.5, 0.45, 0.4), "solid")

    liquid = pfsph_io.frame_files(run_dir, "liquid")
    fluid = pfsph_io.frame_files(run_dir, "fluid")
    frames = sorted(set(liquid) | set(fluid))
    if max_frames:
        frames = frames[:max_frames]
    if not frames:
        raise RuntimeError(f"{run_dir}: no frames")
    first, last = frames[0], frames[-1]
    sc.frame_start, sc.frame_end = first, last
    sc.render.fps = max(1, int(round(fps / interval)))
    templates = _collection("pfsph templates", root)
    templates.hide_render = True

    if liquid:
        coll = _collection("liquid", root)
        for k in frames:
            if k not in liquid:
                continue
            v, t, ff = pfsph_io.read_mesh(liquid[k])
            ob = _mesh_object(f"liquid_{k:05d}", pfsph_io.y_up_to_z_up(v), t, coll)
            ob.data.materials.append(water)
            if "phase" in ff:
                at = ob.data.attributes.new("phase", "INT", "FACE")
                at.data.foreach_set("value", ff["phase"].astype(np.int32))
            vel = pfsph_io.read_mesh_velocity(liquid[k])
            if vel is not None:  # Cycles blurs a mesh's motion by its "velocity" attribute (m/s)
                _add_point_attributes(ob.data, {"velocity": vel})
                report["liquid_velocity"] = True
            _show_only_on(ob, k, first, last)
            report["liquid_faces"][k] = int(len(t))
        report["sets"]["liquid"] = len(coll.objects)
    else:
        coll = _collection("fluid points", root)
        tpl = _point_template("fluid particle", radius, templates)
        tpl.data.materials.append(water)
        for k in frames:
            pts, fields = pfsph_io.read_particles(fluid[k])
            ob = _mesh_object(f"fluid_{k:05d}", pfsph_io.y_up_to_z_up(pts), None, coll)
            _add_point_attributes(ob.data, fields)
            tpl_i = tpl.copy()
            coll.objects.link(tpl_i)
            tpl_i.parent = ob
            ob.instance_type = "VERTS"
            _show_only_on(ob, k, first, last)
            _show_only_on(tpl_i, k, first, last)
        report["sets"]["fluid points"] = len(coll.objects)

    diffuse = pfsph_io.frame_files(run_dir, "diffuse")
    if diffuse:
        coll = _collection("diffuse", root)
        tpls = []
        for i, name in enumerate(DIFFUSE_TYPES):
            t = _point_template(name + " particle", radius * 0.5, templates)
            t.data.materials.append(water if name == "bubble" else foam)
            tpls.append(t)
        for k in frames:
            if k not in diffuse:
                continue
            pts, fields = pfsph_io.read_particles(diffuse[k])
            kind = fields.get("type", fields.get("phase"))
            for i, name in enumerate(DIFFUSE_TYPES):
                sel = kind == i if kind is not None else np.zeros(len(pts), bool)
                ob = _mesh_object(f"{name}_{k:05d}", pfsph_io.y_up_to_z_up(pts[sel]), None, coll)
                # every field as a point attribute (type, lifetime, velocity, ...): shaders and
                # geometry nodes read them; "velocity" also blurs the points' motion in Cycles
                _add_point_attributes(ob.data, {f: a[sel] for f, a in fields.items() if len(a) == len(pts)})
                report.setdefault("diffuse_points", {}).setdefault(name, 0)
                report["diffuse_points"][name] += int(sel.sum())
                if len(ob.data.attributes):
                    report["diffuse_attributes"] = sorted(a.name for a in ob.data.attributes
                                                          if not a.name.startswith(".") and a.name != "position")
                ob.instance_type = "VERTS"
                inst = tpls[i].copy()
                coll.objects.link(inst)
                inst.parent = ob
                _show_only_on(ob, k, first, last)
                _show_only_on(inst, k, first, last)
        report["sets"]["diffuse"] = len(coll.objects)

    solids_ply = os.path.join(run_dir, "solids.ply")
    if os.path.exists(solids_ply):
        # the static solids (tank walls, obstacles): written once per run, one object each, in
        # their phase's colour (scene.json "color"), shown on every frame
        coll = _collection("solids", root)
        v, t, ff, comments = pfsph_io.read_ply(solids_ply)
        pts = np.stack([v["x"], v["y"], v["z"]], axis=1).astype(np.float64)
        phases = scene_json.get("phases", [])
        report["solids"] = {}
        for c in comments:
            w = c.split()
            if len(w) < 4 or w[0] != "solid":  # solid K SHAPE PHASE
                continue
            i, shape, phase = int(w[1]), w[2], " ".join(w[3:])
            sel = ff["solid"] == i
            used = np.unique(t[sel])
            remap = -np.ones(len(pts), np.int64)
            remap[used] = np.arange(len(used))
            ob = _mesh_object(f"solid {i} {shape}", pfsph_io.y_up_to_z_up(pts[used]), remap[t[sel]], coll)
            for p in ob.data.polygons:
                p.use_smooth = shape in ("sphere", "cylinder")
            col = next((ph.get("color") for ph in phases if ph.get("name") == phase and ph.get("color")), None)
            if shape == "container":  # a tank is glass: the water inside shows from any side
                ob.data.materials.append(_material("pfsph glass", tuple(col) if col else (0.9, 0.95, 1.0), "glass"))
            else:
                ob.data.materials.append(_material(f"pfsph solid {phase}", tuple(col) if col else (0.5, 0.45, 0.4),
                                                   "solid"))
            report["solids"][ob.name] = len(ob.data.polygons)
        report["sets"]["solids"] = len(coll.objects)

    bodies_csv = os.path.join(run_dir, "bodies.csv")
    surf = pfsph_io.frame_files(run_dir, "surfaces", ("ply",))
    if os.path.exists(bodies_csv) and surf:
        coll = _collection("bodies", root)
        v, t, ff, comments = pfsph_io.read_ply(next(iter(surf.values())))
        pts = np.stack([v["x"], v["y"], v["z"]], axis=1).astype(np.float64)
        poses = {}
        for c in comments:
            w = c.split()
            if w[0] == "body":  # body i name position x y z quaternion w x y z
                i = int(w[1])
                poses[i] = (np.array([float(a) for a in w[-8:-5]]), tuple(float(a) for a in w[-4:]), w[2])
        objs = {}
        for i, (p0, q0, name) in sorted(poses.items()):
            sel = ff["body"] == i
            used = np.unique(t[sel])
            remap = -np.ones(len(pts), np.int64)
            remap[used] = np.arange(len(used))
            local = _quat_rotate_inv(q0, pts[used] - p0)  # the body's own frame, pfsph axes
            ob = _mesh_object(f"body {name}", pfsph_io.y_up_to_z_up(local), remap[t[sel]], coll)
            ob.data.materials.append(solid)
            ob.rotation_mode = "QUATERNION"
            objs[i] = ob
        with open(bodies_csv) as f:
            for row in csv.DictReader(f):
                fr = int(row["frame"])
                if fr % interval or fr // interval > last:
                    continue
                ob = objs.get(int(row["body"]))
                if ob is None:
                    continue
                x = np.array([[float(row["x"]), float(row["y"]), float(row["z"])]])
                ob.location = tuple(pfsph_io.y_up_to_z_up(x)[0])
                ob.rotation_quaternion = _quat_y_to_z(tuple(float(row[k]) for k in ("qw", "qx", "qy", "qz")))
                ob.keyframe_insert("location", frame=fr // interval)
                ob.keyframe_insert("rotation_quaternion", frame=fr // interval)
        report["sets"]["bodies"] = len(objs)
        report["bodies"] = {}
        for i, ob in objs.items():
            fc = [f for f in ob.animation_data.action.fcurves if f.data_path == "location" and f.array_index == 2]
            keys = [(k.co[0], k.co[1]) for k in fc[0].keyframe_points] if fc else []
            report["bodies"][ob.name] = {"keys": len(keys), "faces": len(ob.data.polygons),
                                         "z_first": round(keys[0][1], 6) if keys else None,
                                         "z_last": round(keys[-1][1], 6) if keys else None}

    report["objects"] = len(root.all_objects)
    report["frame_start"], report["frame_end"] = first, last
    report["fps"] = sc.render.fps
    return report


def _main(argv):
    args = argv[argv.index("--") + 1:] if "--" in argv else []
    if not args:
        print("usage: blender -b -P pfsph_load.py -- RUN_DIR [--save FILE.blend] [--report FILE.json]")
        print("  clears the startup scene (default cube, camera, light), loads the run and adds its stage:")
        print("  the scene's camera, a sun, a grey world and a floor")
        return 2
    run_dir, save, rep = args[0], None, None
    if "--save" in args:
        save = args[args.index("--save") + 1]
    if "--report" in args:
        rep = args[args.index("--report") + 1]
    clear_startup()
    report = load_run(run_dir)
    with open(os.path.join(run_dir, "scene.json")) as f:
        setup_stage(json.load(f))
    report["stage"] = sorted(o.name for o in bpy.context.scene.collection.objects)
    print("pfsph_load: " + json.dumps(report, sort_keys=True))
    if rep:
        with open(rep, "w") as f:
            json.dump(report, f, sort_keys=True)
    if save:
        bpy.ops.wm.save_as_mainfile(filepath=os.path.abspath(save))
    return 0


if __name__ == "__main__":
    rc = _main(sys.argv)
    if rc:
        sys.exit(rc)
