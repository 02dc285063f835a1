"""World of the suturing scene: the stereo camera pair cameraL/cameraR on the CameraFrame body
(as the challenge's world_stereo.yaml: 4 mm baseline, looking along the frame's -z), lights
with shadows, and a checkered floor as the environment model."""

from __future__ import annotations

import io

import numpy as np

from ...model import (
    Attenuation,
    Body,
    ClippingPlane,
    Friction,
    Geometry,
    Light,
    ModelFile,
    Pose,
    Resolution,
    Vec3,
    World,
)

EYE_SEPARATION = 0.004
FIELD_OF_VIEW = 1.2


def build_world() -> World:
    w = World(namespace="/ambf/env/", gravity=Vec3(0.0, 0.0, -9.81), max_iterations=50, environment="./floor.yaml")
    from ...model import Camera

    for name, dx, monitor in (("cameraL", -EYE_SEPARATION / 2, 1), ("cameraR", EYE_SEPARATION / 2, 2)):
        w.cameras.append(
            Camera(
                identifier=name,
                name=name,
                namespace="cameras/",
                parent="BODY CameraFrame",
                location=Vec3(dx, 0.0, 0.0),
                look_at=Vec3(dx, 0.0, -1.0),
                up=Vec3(0.0, 1.0, 0.0),
                clipping_plane=ClippingPlane(near=0.001, far=10.0),
                field_view_angle=FIELD_OF_VIEW,
                monitor=monitor,
                publish_image=True,
                publish_image_interval=5,
                publish_depth=True,
                publish_image_resolution=Resolution(width=640, height=480),
            )
        )
    w.lights.append(
        Light(
            identifier="light1",
            name="light1",
            namespace="lights/",
            location=Vec3(0.1, 0.3, 1.2),
            direction=Vec3(-0.08, -0.25, -1.0),
            spot_exponent=0.3,
            cutoff_angle=0.7,
            shadow_quality=5,
        )
    )
    w.lights.append(
        Light(
            identifier="light2",
            name="light2",
            namespace="lights/",
            parent="BODY CameraFrame",
            location=Vec3(0.0, 0.0, 0.0),
            direction=Vec3(0.0, 0.0, -1.0),
            spot_exponent=0.9,
            cutoff_angle=1.6,
            shadow_quality=2,
            attenuation=Attenuation(constant=0.8, linear=0.8, quadratic=0.0),
        )
    )
    return w


def build_floor() -> ModelFile:
    m = ModelFile(namespace="/ambf/env/", high_resolution_path="./meshes/", low_resolution_path="./meshes/")
    g = Geometry(x=1.0, y=1.0, z=0.02)
    m.bodies.append(
        Body(
            identifier="BODY Floor",
            name="Floor",
            mass=0.0,
            location=Pose(Vec3(0.0, 0.0, 0.0)),
            mesh="Floor.OBJ",
            use_material=True,
            collision_shape="Box",
            collision_geometry=g,
            collision_offset=Pose(Vec3(0.0, 0.0, -0.01)),
            collision_margin=0.001,
            friction=Friction(static=0.9, rolling=0.1),
            restitution=0.1,
            passive=False,
        )
    )
    return m


def floor_obj_text() -> str:
    from .meshes import boxes_mesh, obj_text

    v, uv, f = boxes_mesh([((-0.5, -0.5, -0.02), (0.5, 0.5, 0.0))], 0.1)
    return obj_text(v, f, uvs=uv, mtllib="Floor.mtl", material="checker", comment="floor, written by adfkit")


def floor_mtl_text() -> str:
    return "newmtl checker\nKa 0.3 0.3 0.3\nKd 1.0 1.0 1.0\nKs 0.0 0.0 0.0\nd 1\nmap_Kd checker.png\n"


def checker_png(size: int = 64) -> bytes:
    from PIL import Image

    i = np.arange(size) // (size // 2)
    board = (i[:, None] + i[None, :]) % 2
    a = np.where(board[:, :, None] == 1, (150, 150, 155), (95, 95, 100)).astype(np.uint8)
    buf = io.BytesIO()
    Image.fromarray(a).save(buf, format="PNG", optimize=True)
    return buf.getvalue()
