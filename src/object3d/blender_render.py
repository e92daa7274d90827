# vfcapture's adapter for 3D models: Blender renders a textured model from given cameras.
#
# Run by src/object3d/blender.c as
#     blender -b --factory-startup -t THREADS --python blender_render.py -- JOB.json
# JOB.json says what to render:
#     model        the .glb / .gltf / .obj / .blend file
#     normalize    {"center": [x, y, z], "scale": s} to reuse a recorded transform, or null to
#                  centre the model's bounding box at the origin and scale it into the unit sphere
#     width, height, fx, fy, cx, cy   the pinhole camera (pixels)
#     samples      Cycles samples a pixel (adaptive sampling; this build has no denoiser)
#     scene        "studio" (default: white light from everywhere, transparent background) or
#                  "room" (the object stands on a textured floor inside a textured wall, opaque
#                  RGB: what a photo of it in a room gives structure from motion to hold on to)
#     shutter      > 0: the views are the consecutive frames of a video (the studio's phone):
#                  the camera is keyframed at every view and Cycles blurs each frame over this
#                  share of the frame interval (0.5: a 1/60 s shutter at 30 fps); 0: stills
#     views        [{"file": NAME.png, "c2w": 16 numbers}], camera-to-world, row-major,
#                  OpenGL axes (x right, y up, looking along -z), in the normalized object frame
#                  (z up: Blender's own world axes; the glTF importer turns y-up into z-up)
#     output_dir   where the PNGs go (8 bit, sRGB; RGBA with a transparent background in the
#                  studio)
#     info         where to write what was measured: the transform, vertex and mesh counts
#     serve        true: no views; render one view a request arriving on file descriptor 3
#                  until it closes (serve() below: a camera that moves as the caller says)
# It prints one "vf-view I N FILE" line a finished view and "vf-error: MESSAGE" before a
# non-zero exit (2: the input is at fault, 4: the installation), so the C side can show
# progress and one clear error line. Views whose PNG
# already exists are skipped (an interrupted ingest resumes), and every PNG is written under a
# temporary name first, so a killed render never leaves a half-written image.
import json
import os
import shutil
import sys


def leave(code):
    # os._exit skips Blender's own exit, which would remove its /tmp/blender_* folder
    bpy = sys.modules.get("bpy")
    if bpy is not None and bpy.app.tempdir:
        shutil.rmtree(bpy.app.tempdir, ignore_errors=True)
    sys.stdout.flush()
    os._exit(code)


def fail(message, code=2):
    print("vf-error: " + message, flush=True)
    leave(code)


try:
    import numpy
    # Debian 12's Blender 3.4 importer still uses np.bool, which numpy 1.24 removed.
    if not hasattr(numpy, "bool"):
        numpy.bool = bool
except ImportError:
    fail("Blender's Python has no numpy, which its glTF importer needs: "
         "apt-get install python3-numpy", 4)

import bpy
import mathutils

argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
if len(argv) != 1:
    fail("usage: blender -b --python blender_render.py -- JOB.json")
with open(argv[0]) as f:
    job = json.load(f)


def import_model(path):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    ext = os.path.splitext(path)[1].lower()
    try:
        if ext in (".glb", ".gltf"):
            bpy.ops.import_scene.gltf(filepath=path)
        elif ext == ".obj":
            bpy.ops.wm.obj_import(filepath=path)
        elif ext == ".blend":
            bpy.ops.wm.open_mainfile(filepath=path)
        else:
            fail("cannot read %s: give a .glb, .gltf, .obj or .blend file" % path)
    except Exception as e:  # the importer's own words name the missing extension
        text = " ".join(str(e).split())
        if "Extension" in text and "not available" in text:
            start = text.find("Extension")
            fail("%s needs a glTF extension Blender's importer lacks (%s); convert it to a "
                 "plain .glb first, e.g. npx @gltf-transform/cli copy IN.glb OUT.glb"
                 % (path, text[start:start + 120].split(" is ")[0]))
        if "draco" in text.lower():
            fail("%s is Draco-compressed and this Blender has no Draco decoder; convert it to a "
                 "plain .glb first, e.g. npx @gltf-transform/cli copy IN.glb OUT.glb" % path)
        fail("Blender cannot import %s: %s" % (path, text[:300]))


def first_frame():
    scene = bpy.context.scene
    starts = [a.frame_range[0] for a in bpy.data.actions]
    scene.frame_set(int(min(starts)) if starts else scene.frame_start)


def world_vertices(meshes):
    depsgraph = bpy.context.evaluated_depsgraph_get()
    chunks = []
    for obj in meshes:
        ev = obj.evaluated_get(depsgraph)
        mesh = ev.to_mesh()
        n = len(mesh.vertices)
        if n:
            co = numpy.empty(n * 3, dtype=numpy.float64)
            mesh.vertices.foreach_get("co", co)
            co = co.reshape(n, 3)
            m = numpy.array(ev.matrix_world)
            chunks.append(co @ m[:3, :3].T + m[:3, 3])
        ev.to_mesh_clear()
    return numpy.concatenate(chunks) if chunks else numpy.zeros((0, 3))


def normalize(meshes, recorded):
    points = world_vertices(meshes)
    if len(points) == 0:
        fail("%s has no geometry to render (no mesh with vertices)" % job["model"])
    if recorded:
        center = numpy.array(recorded["center"], dtype=numpy.float64)
        scale = float(recorded["scale"])
    else:
        center = (points.min(axis=0) + points.max(axis=0)) / 2
        radius = numpy.sqrt(((points - center) ** 2).sum(axis=1)).max()
        if not radius > 0:
            fail("%s renders empty: all its vertices are at one point" % job["model"])
        scale = 1.0 / radius
    # One parent moves everything: x_object = scale * (x_blender - center).
    root = bpy.data.objects.new("vf_normalize", None)
    bpy.context.scene.collection.objects.link(root)
    for obj in list(bpy.context.scene.objects):
        if obj.parent is None and obj is not root:
            world = obj.matrix_world.copy()
            obj.parent = root
            obj.matrix_world = world
    root.matrix_world = (mathutils.Matrix.Scale(scale, 4) @
                         mathutils.Matrix.Translation(mathutils.Vector(-center)))
    bpy.context.view_layer.update()
    moved = world_vertices(meshes)
    return {"center": center.tolist(), "scale": scale, "vertices": int(len(points)),
            "meshes": len(meshes), "bbox_min": moved.min(axis=0).tolist(),
            "bbox_max": moved.max(axis=0).tolist(),
            "radius": float(numpy.sqrt((moved ** 2).sum(axis=1)).max())}


def setup_scene():
    scene = bpy.context.scene
    for obj in list(scene.objects):  # a controlled scene: our camera, our light
        if obj.type in ("LIGHT", "CAMERA"):
            bpy.data.objects.remove(obj, do_unlink=True)
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = int(job.get("samples", 64))
    scene.cycles.use_adaptive_sampling = True
    scene.cycles.use_denoising = False  # Debian's build has no OpenImageDenoise
    scene.cycles.max_bounces = 8
    scene.render.use_persistent_data = True  # textures and BVH stay loaded from view to view
    scene.render.film_transparent = True
    scene.view_settings.view_transform = "Standard"  # white stays white, colours as textured
    scene.view_settings.look = "None"
    scene.render.resolution_x = int(job["width"])
    scene.render.resolution_y = int(job["height"])
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = "PNG"
    scene.render.image_settings.color_mode = "RGBA"
    scene.render.image_settings.color_depth = "8"
    # A white studio: uniform white light from every direction, plus a soft key light above.
    world = bpy.data.worlds.new("vf_world")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs[0].default_value = (1, 1, 1, 1)
    world.node_tree.nodes["Background"].inputs[1].default_value = 1.0
    scene.world = world
    sun = bpy.data.lights.new("vf_key", "SUN")
    sun.energy = 2.0
    sun.angle = 0.5
    key = bpy.data.objects.new("vf_key", sun)
    key.rotation_euler = (0.6, 0.2, 0.8)
    scene.collection.objects.link(key)

    cam_data = bpy.data.cameras.new("vf_camera")
    w, h = float(job["width"]), float(job["height"])
    fx, fy = float(job["fx"]), float(job["fy"])
    cam_data.sensor_fit = "AUTO"  # the sensor spans the larger side
    cam_data.sensor_width = 36.0
    cam_data.lens = (fx if w >= h else fy) * cam_data.sensor_width / max(w, h)
    cam_data.shift_x = (w / 2 - float(job["cx"])) / max(w, h)
    cam_data.shift_y = (float(job["cy"]) - h / 2) / max(w, h)
    scene.render.pixel_aspect_x = 1.0
    scene.render.pixel_aspect_y = fx / fy if w >= h else 1.0
    cam_data.clip_start = 0.01
    cam_data.clip_end = 100.0
    camera = bpy.data.objects.new("vf_camera", cam_data)
    scene.collection.objects.link(camera)
    scene.camera = camera
    return scene, camera


def textured_material(name, scale, colors, glow=0.0):
    """A procedural material that looks different everywhere (multi-scale noise over Voronoi
    cells, like stone): corners for SIFT at every scale, and none of the repetition of tiles
    or bricks, whose copies SIFT cannot tell apart."""
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    bsdf = nodes["Principled BSDF"]
    bsdf.inputs["Roughness"].default_value = 0.8
    coords = nodes.new("ShaderNodeTexCoord")
    noise = nodes.new("ShaderNodeTexNoise")
    noise.inputs["Scale"].default_value = scale
    noise.inputs["Detail"].default_value = 6
    noise.inputs["Roughness"].default_value = 0.65
    cells = nodes.new("ShaderNodeTexVoronoi")
    cells.inputs["Scale"].default_value = scale * 3
    links.new(coords.outputs["Object"], noise.inputs["Vector"])
    links.new(coords.outputs["Object"], cells.inputs["Vector"])
    mix = nodes.new("ShaderNodeMath")
    mix.operation = "MULTIPLY_ADD"  # noise * 0.7 + cell distance
    mix.inputs[1].default_value = 0.7
    links.new(noise.outputs["Fac"], mix.inputs[0])
    links.new(cells.outputs["Distance"], mix.inputs[2])
    ramp = nodes.new("ShaderNodeValToRGB")
    ramp.color_ramp.elements[0].position = 0.3
    ramp.color_ramp.elements[0].color = colors[0]
    ramp.color_ramp.elements[1].position = 1.0
    ramp.color_ramp.elements[1].color = colors[1]
    links.new(mix.outputs["Value"], ramp.inputs["Fac"])
    links.new(ramp.outputs["Color"], bsdf.inputs["Base Color"])
    if glow > 0:  # a wall lit evenly from the room: little of the sky reaches it, and few
        links.new(ramp.outputs["Color"], bsdf.inputs["Emission"])  # samples are noise there
        bsdf.inputs["Emission Strength"].default_value = glow
        mat.cycles.sample_as_light = False  # a faint glow over a huge wall: sampling it as a
                                            # lamp costs 20% of the time and adds noise
    return mat


def add_room(scene, floor_z):
    """A floor under the object (at its lowest point) and an open-topped round wall, far enough
    that the cameras at distance 4 stay inside; the white sky still lights it from above."""
    bpy.ops.mesh.primitive_plane_add(size=30.0, location=(0, 0, floor_z))
    floor = bpy.context.active_object
    floor.data.materials.append(textured_material(
        "vf_floor", 1.5, [(0.15, 0.1, 0.06, 1), (0.85, 0.65, 0.45, 1)]))
    bpy.ops.mesh.primitive_cylinder_add(vertices=64, radius=12.0, depth=16.0, end_fill_type="NOTHING",
                                        location=(0, 0, floor_z + 8.0))
    wall = bpy.context.active_object
    wall.data.materials.append(textured_material(
        "vf_wall", 0.8, [(0.25, 0.3, 0.4, 1), (0.9, 0.9, 0.85, 1)], glow=0.3))
    scene.render.film_transparent = False
    scene.render.image_settings.color_mode = "RGB"
    scene.cycles.max_bounces = 3  # diffuse walls: more bounces cost time, not features


import_model(job["model"])
first_frame()
meshes = [o for o in bpy.context.scene.objects if o.type == "MESH"]
info = normalize(meshes, job.get("normalize"))
scene, camera = setup_scene()
if job.get("scene", "studio") == "room":
    # the floor at the object's lowest point: from the fit, or from the vertices when the
    # transform was given
    add_room(scene, float(numpy.array(world_vertices(meshes))[:, 2].min()))
elif job.get("scene", "studio") != "studio":
    fail("unknown scene %r: use studio or room" % job.get("scene"))
with open(job["info"] + ".tmp", "w") as f:
    json.dump(info, f, indent=1)
os.replace(job["info"] + ".tmp", job["info"])



def matrix(c2w):
    return mathutils.Matrix([c2w[0:4], c2w[4:8], c2w[8:12], c2w[12:16]])


def keyframe_path(scene, camera, views, shutter):
    """The camera moves through the views, one a frame, so that motion blur sees its motion.
    The model stays as it is now (an animated model keeps its first frame)."""
    for obj in scene.objects:
        if obj is not camera and obj.animation_data:
            obj.animation_data_clear()
    camera.rotation_mode = "QUATERNION"
    previous = None
    for i, view in enumerate(views):
        camera.matrix_world = matrix(view["c2w"])
        q = camera.rotation_quaternion.copy()
        if previous is not None and q.dot(previous) < 0:
            q.negate()  # the same rotation; the one that interpolates the short way
        camera.rotation_quaternion = q
        previous = q
        camera.keyframe_insert("location", frame=i + 1)
        camera.keyframe_insert("rotation_quaternion", frame=i + 1)
    for curve in camera.animation_data.action.fcurves:
        for key in curve.keyframe_points:
            key.interpolation = "LINEAR"
    scene.render.use_motion_blur = True
    scene.render.motion_blur_shutter = shutter


def serve(scene, camera):
    """A live camera (the studio's closed loop): the caller's requests arrive on the socket
    that is file descriptor 3, one JSON line each, {"c2w": 16 numbers, "file": NAME.png};
    each is rendered into output_dir and answered "done NAME.png" (or "vf-error: ..."). The
    first line sent is "ready" (the model is loaded). The socket's end ends the loop."""
    import socket
    channel = socket.socket(fileno=3)
    channel.sendall(b"ready\n")
    for line in channel.makefile("r"):
        try:
            request = json.loads(line)
            camera.matrix_world = matrix(request["c2w"])
            name = os.path.basename(request["file"])
        except (ValueError, KeyError, TypeError) as e:
            channel.sendall(("vf-error: bad request: %s\n" % e).encode())
            continue
        out = os.path.join(job["output_dir"], name)
        scene.render.filepath = out + ".partial.png"
        bpy.ops.render.render(write_still=True)
        os.replace(out + ".partial.png", out)
        channel.sendall(("done %s\n" % name).encode())
    leave(0)


if job.get("serve"):
    serve(scene, camera)
views = job["views"]
shutter = float(job.get("shutter", 0))
if shutter > 0:
    keyframe_path(scene, camera, views, shutter)
for i, view in enumerate(views):
    out = os.path.join(job["output_dir"], view["file"])
    if not os.path.exists(out):
        if shutter > 0:
            scene.frame_set(i + 1)
        else:
            camera.matrix_world = matrix(view["c2w"])
        partial = out + ".partial.png"
        scene.render.filepath = partial
        bpy.ops.render.render(write_still=True)
        os.replace(partial, out)
    print("vf-view %d %d %s" % (i + 1, len(views), view["file"]), flush=True)
