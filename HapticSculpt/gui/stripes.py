"""Zebra stripes and reflection lines per pixel (GUI only): a GLSL fragment shader through Coin's
SoShaderProgram shades every pixel from the exact B-spline normal, read from a normal texture
sampled from the surface (not interpolated mesh normals), so the stripes stay smooth at any zoom.

Two modes: "reflection" (view-dependent: the eye ray mirrored in the surface, across light strips
that run at ``angle`` degrees from the view's up direction) and "isophote" (world-fixed: bands of
equal angle between the normal and ``direction``). ``stripes`` sets the number of bands over a
half turn; :data:`DIRECTIONS` are the directions the workbench's command cycles through. Where the driver
runs no GLSL, :func:`shaders_work` says so once and the overlay falls back to per-vertex colours.
No Qt: pivy only.
"""
from __future__ import annotations

from typing import Any

import numpy as np

MODES = ("reflection", "isophote")
#: The stripe directions "Zebra: direction" cycles through: its name, the reflection strips' angle
#: from the view's up direction (degrees) and the isophotes' world direction.
DIRECTIONS = (("vertical, to +Z", 0.0, (0.0, 0.0, 1.0)), ("horizontal, to +X", 90.0, (1.0, 0.0, 0.0)),
              ("diagonal, to +Y", 45.0, (0.0, 1.0, 0.0)),
              ("other diagonal, to +X+Y+Z", 135.0, (0.5773502691896258, 0.5773502691896258, 0.5773502691896258)))
TEXTURE = 256  # normal texture resolution per side while the surface rests (128 while sculpting)

VERTEX = """
varying vec2 uv;
varying vec3 eyePosition;
void main() {
    uv = gl_MultiTexCoord0.st;
    eyePosition = (gl_ModelViewMatrix * gl_Vertex).xyz;
    gl_Position = ftransform();
}
"""

# Bands from a triangle wave of the phase, edges smoothed over one pixel's change of phase (fwidth):
# anti-aliased at any zoom.
FRAGMENT = """
uniform sampler2D normalsHigh;
uniform sampler2D normalsLow;
uniform float size;
uniform float stripes;
uniform int reflection;
uniform float angle;
uniform float directionX;
uniform float directionY;
uniform float directionZ;
varying vec2 uv;
varying vec3 eyePosition;
// One texel's normal from its high and low bytes: 16 bits a component (8 would show as jagged edges).
vec3 texel(vec2 ij) {
    vec2 at = (ij + 0.5) / size;
    vec3 high = texture2D(normalsHigh, at).xyz * 255.0;
    vec3 low = texture2D(normalsLow, at).xyz * 255.0;
    return (floor(high + 0.5) * 256.0 + floor(low + 0.5)) / 65535.0 * 2.0 - 1.0;
}
void main() {
    vec2 p = clamp(uv * size - 0.5, 0.0, size - 1.001);
    vec2 i = floor(p);
    vec2 f = p - i;
    vec3 n0 = mix(texel(i), texel(i + vec2(1.0, 0.0)), f.x);
    vec3 n1 = mix(texel(i + vec2(0.0, 1.0)), texel(i + vec2(1.0, 1.0)), f.x);
    vec3 n = normalize(gl_NormalMatrix * mix(n0, n1, f.y));
    float phase;
    if (reflection == 1) {
        // the eye ray: along -z for an orthographic camera (FreeCAD's default), through the point otherwise
        vec3 eye = gl_ProjectionMatrix[3][3] == 1.0 ? vec3(0.0, 0.0, -1.0) : normalize(eyePosition);
        vec3 r = reflect(eye, n);
        phase = asin(clamp(r.x * cos(angle) + r.y * sin(angle), -1.0, 1.0)) / 3.14159265;
    } else {
        vec3 d = normalize(gl_NormalMatrix * vec3(directionX, directionY, directionZ));
        phase = acos(clamp(dot(n, d), -1.0, 1.0)) / 3.14159265;
    }
    float x = phase * stripes;
    float w = max(fwidth(x), 1e-4);
    float triangle = abs(fract(0.5 * x) - 0.5) * 2.0;
    float band = smoothstep(0.5 - w, 0.5 + w, triangle);
    gl_FragColor = vec4(vec3(band), 1.0);
}
"""

MESH = 97  # the shaded mesh's points per side: exact surface points, so it hugs the Part face


def sample(surface: Any, size: int) -> tuple[np.ndarray, tuple[bytes, bytes]]:
    """The surface for the shader: exact points on a MESH x MESH grid over the domain, and the
    exact unit normals on a size x size grid as a texture (:func:`normal_texture`)."""
    points, _ = surface.grid(MESH, MESH)
    _, normals = surface.grid(size, size)
    return np.asarray(points), normal_texture(np.asarray(normals))


def normal_texture(n: np.ndarray) -> tuple[bytes, bytes]:
    """Unit normals on a grid ([i along u, j along v]), each component (n + 1) / 2 in 16 bits, as
    two RGB images (high bytes, low bytes), rows along v, columns along u (the texture's t and s)."""
    q = np.clip(np.rint((np.transpose(n, (1, 0, 2)) + 1.0) * 0.5 * 65535.0), 0, 65535).astype(np.uint32)
    return (q >> 8).astype(np.uint8).tobytes(), (q & 0xFF).astype(np.uint8).tobytes()


def _shader(coin: Any, vertex: str | None, fragment: str, params: list[Any]) -> Any:
    program = coin.SoShaderProgram()
    objects = []
    if vertex is not None:
        vs = coin.SoVertexShader()
        vs.sourceType = coin.SoShaderObject.GLSL_PROGRAM
        vs.sourceProgram = vertex
        objects.append(vs)
    fs = coin.SoFragmentShader()
    fs.sourceType = coin.SoShaderObject.GLSL_PROGRAM
    fs.sourceProgram = fragment
    for k, p in enumerate(params):
        fs.parameter.set1Value(k, p)
    objects.append(fs)
    for k, o in enumerate(objects):
        program.shaderObject.set1Value(k, o)
    return program


def _param(coin: Any, kind: str, name: str, value: Any) -> Any:
    p = getattr(coin, kind)()
    p.name = name
    p.value = value
    return p


def stripe_mesh(mesh: np.ndarray, texture: tuple[bytes, bytes], size: int, mode: str, stripes: float,
                direction: tuple[float, float, float], quads: list[int], angle: float = 0.0) -> Any:
    """The surface shaded per pixel: ``mesh`` its points on an even grid over the domain (from
    :func:`sample`), ``texture`` the normal texture of ``size`` x ``size`` texels, ``quads`` the
    mesh's face indices; ``angle`` (degrees) turns the reflection strips from the view's up direction."""
    from pivy import coin
    g, h = mesh.shape[:2]
    us, vs = np.linspace(0.0, 1.0, g), np.linspace(0.0, 1.0, h)
    sep = coin.SoSeparator()
    # A hair toward the viewer where the surface is steep on screen; the overlay lifts the whole
    # display in front of the face by its tessellation's deviation (Overlay._lift).
    offset = coin.SoPolygonOffset()
    offset.factor = -1.0
    offset.units = -1.0
    sep.addChild(offset)
    complexity = coin.SoComplexity()
    complexity.textureQuality = 0.1  # nearest texels, no mipmaps (0 would switch texturing off): the shader
    # interpolates the decoded normals itself
    sep.addChild(complexity)
    for unit, image in enumerate(texture):
        chooser = coin.SoTextureUnit()
        chooser.unit = unit
        sep.addChild(chooser)
        tex = coin.SoTexture2()
        tex.image.setValue(coin.SbVec2s(size, size), 3, image)
        tex.wrapS = coin.SoTexture2.CLAMP
        tex.wrapT = coin.SoTexture2.CLAMP
        sep.addChild(tex)
    chooser = coin.SoTextureUnit()
    chooser.unit = 0
    sep.addChild(chooser)
    sep.addChild(_shader(coin, VERTEX, FRAGMENT, [
        _param(coin, "SoShaderParameter1i", "normalsHigh", 0),
        _param(coin, "SoShaderParameter1i", "normalsLow", 1),
        _param(coin, "SoShaderParameter1f", "size", float(size)),
        _param(coin, "SoShaderParameter1f", "stripes", float(stripes)),
        _param(coin, "SoShaderParameter1i", "reflection", 1 if mode == "reflection" else 0),
        _param(coin, "SoShaderParameter1f", "angle", float(np.radians(angle))),
        # (three floats: a vec3 parameter did not reach the shader through pivy)
        _param(coin, "SoShaderParameter1f", "directionX", float(direction[0])),
        _param(coin, "SoShaderParameter1f", "directionY", float(direction[1])),
        _param(coin, "SoShaderParameter1f", "directionZ", float(direction[2]))]))
    coords = coin.SoCoordinate3()
    coords.point.setValues(0, g * h, mesh.reshape(-1, 3).tolist())
    sep.addChild(coords)
    st = np.stack(np.meshgrid(us, vs, indexing="ij"), axis=-1).reshape(-1, 2)
    texcoords = coin.SoTextureCoordinate2()
    texcoords.point.setValues(0, g * h, st.tolist())
    sep.addChild(texcoords)
    binding = coin.SoTextureCoordinateBinding()
    binding.value = coin.SoTextureCoordinateBinding.PER_VERTEX_INDEXED
    sep.addChild(binding)
    faces = coin.SoIndexedFaceSet()
    faces.coordIndex.setValues(0, len(quads), quads)
    sep.addChild(faces)
    return sep


GL_SHADING_LANGUAGE_VERSION = 0x8B8C
_GLSL: list[str] = []  # the driver's GLSL version ("" for none) once a render has told


def shaders_work() -> bool | None:
    """Whether this OpenGL runs GLSL: None until a render has told (see :func:`probe`). The first
    time the answer is no, says so on the report view; the overlay then colours per vertex."""
    return bool(_GLSL[0]) if _GLSL else None


def probe() -> Any:
    """A node that asks the OpenGL driver for its GLSL version while it renders (the context is
    current only then), through ctypes on libGL: no Qt, nothing drawn."""
    from pivy import coin

    def ask(_data: Any, action: Any) -> None:
        if _GLSL or not action.isOfType(coin.SoGLRenderAction.getClassTypeId()):
            return
        version = ""
        try:
            import ctypes
            gl = ctypes.CDLL("libGL.so.1")
            gl.glGetString.restype = ctypes.c_char_p
            gl.glGetString.argtypes = [ctypes.c_uint]
            version = (gl.glGetString(GL_SHADING_LANGUAGE_VERSION) or b"").decode(errors="replace")
        except (OSError, AttributeError):
            version = ""
        _GLSL.append(version)
        if not version:
            import FreeCAD
            FreeCAD.Console.PrintWarning("HapticSculpt: this OpenGL driver runs no GLSL shaders: zebra stripes "
                                         "and reflection lines are coloured per mesh vertex instead of per pixel\n")
    node = coin.SoCallback()
    node.setCallback(ask)
    return node
