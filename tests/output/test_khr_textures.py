"""A .glb written by another tool with KHR_materials_iridescence at iridescenceFactor 0.5,
a factor texture and a thickness texture: it imports with those values, draws its film
with its own thickness texture (not the preset's field), and exports them back, texel for
texel; a broken texture is refused with a message naming it."""

from __future__ import annotations

import io

import numpy as np
import pygltflib
import pytest
from PIL import Image

from mesh_helpers import glb_with_film
from opaline.local.context import local_context
from opaline.local.export import export_material, import_material
from opaline.model.params import Material, RenderRequest
from opaline.model.presets import build_assets, build_thickness, get_preset
from opaline.output.gltf import export_glb
from opaline.pipeline.prepare import prepare
from opaline.scene.gltf_film import read_film_textures

KHR = "KHR_materials_iridescence"
RNG = np.random.default_rng(31)
THICKNESS = RNG.integers(0, 256, (48, 64)).astype(np.uint8)  # not square: rows stay rows
FACTOR = RNG.integers(0, 256, (32, 32)).astype(np.uint8)


def png(channel: np.ndarray, index: int) -> bytes:
    """A texture whose KHR channel holds ``channel`` and whose others hold noise (KHR reads
    G of the thickness texture and R of the factor texture, nothing else)."""
    rgb = RNG.integers(0, 256, (*channel.shape, 3)).astype(np.uint8)
    rgb[..., index] = channel
    out = io.BytesIO()
    Image.fromarray(rgb, "RGB").save(out, "PNG")
    return out.getvalue()


def other_tools_glb(thickness_png: bytes | None = None) -> bytes:
    """The sphere (it has UVs) as a .glb with a film of factor 0.5 and both textures."""
    mesh, _ = build_assets(get_preset("sphere"))
    document = pygltflib.GLTF2.load_from_bytes(export_glb(mesh, Material()))
    images = {"iridescenceThicknessTexture": thickness_png or png(THICKNESS, 1),
              "iridescenceTexture": png(FACTOR, 0)}
    film = {"iridescenceFactor": 0.5, "iridescenceIor": 1.4,
            "iridescenceThicknessMinimum": 200.0, "iridescenceThicknessMaximum": 800.0}
    return glb_with_film(document, images, film)


def test_imports_draws_and_exports_the_factor_and_both_textures(tmp_path):
    path = tmp_path / "film.glb"
    path.write_bytes(other_tools_glb())
    fields = import_material(path, preset="nacre-film")
    assert fields["film_weight"] == 0.5 and fields["mesh"] == str(path)
    assert (fields["film_thickness_min"], fields["film_thickness_max"]) == (200.0, 800.0)

    # The film is drawn with the file's thickness texture, in the mesh's UVs, not with
    # nacre-film's tablets projected over it.
    request = RenderRequest.model_validate(fields)
    preset = prepare(request, local_context(cost_budget=None)).preset
    assert preset.thickness_map is not None and preset.thickness_map.kind == "glb"
    assert preset.mesh_projection == "auto"
    np.testing.assert_array_equal(build_thickness(preset), THICKNESS / np.float32(255.0))

    exported = read_film_textures(export_material(fields, "glb"))
    document = pygltflib.GLTF2.load_from_bytes(export_material(fields, "glb"))
    film = document.materials[0].extensions[KHR]
    assert film["iridescenceFactor"] == 0.5
    assert (film["iridescenceThicknessMinimum"], film["iridescenceThicknessMaximum"]) == (
        200.0, 800.0)
    assert exported.thickness is not None and exported.factor is not None
    np.testing.assert_array_equal(np.round(exported.thickness * 255.0), THICKNESS)
    np.testing.assert_array_equal(np.round(exported.factor * 255.0), FACTOR)


def test_a_glb_without_film_textures_keeps_its_presets_field(tmp_path):
    path = tmp_path / "plain.glb"
    path.write_bytes(export_material({"preset": "sphere"}, "glb"))
    preset = prepare(RenderRequest(preset="nacre-film", mesh=str(path)),
                     local_context(cost_budget=None)).preset
    assert preset.thickness_map == get_preset("nacre-film").thickness_map


@pytest.mark.parametrize("raw,message", [
    (b"not an image", "not a readable image"),
    (b"GIF89a" + bytes(64), "not a readable image"),
], ids=["garbage", "truncated-gif"])
def test_a_broken_texture_is_refused_naming_it(tmp_path, raw, message):
    with pytest.raises(ValueError, match=f"iridescenceThicknessTexture: {message}"):
        read_film_textures(other_tools_glb(thickness_png=raw))


def test_a_huge_texture_is_refused_before_it_is_decoded(monkeypatch):
    monkeypatch.setattr("opaline.scene.gltf_film.MAX_TEXELS", 100)
    with pytest.raises(ValueError, match="64×48 texels, more than 100"):
        read_film_textures(other_tools_glb())


def _edited(edit) -> bytes:
    """other_tools_glb() with its JSON edited by ``edit`` (a dict), the binary chunk kept:
    what a hostile writer can put there, which pygltflib itself would not write."""
    import json
    import struct

    data = other_tools_glb()
    length = struct.unpack("<I", data[12:16])[0]
    header = json.loads(data[20:20 + length])
    edit(header)
    text = json.dumps(header).encode()
    text += b" " * (-len(text) % 4)
    rest = data[20 + length:]
    body = struct.pack("<I", len(text)) + b"JSON" + text + rest
    return b"glTF" + struct.pack("<II", 2, 12 + len(body)) + body


def _png_header(width: int, height: int) -> bytes:
    """A PNG that declares a size and holds no pixels: what a decompression bomb starts as."""
    import struct
    import zlib

    def chunk(kind: bytes, body: bytes) -> bytes:
        return (struct.pack(">I", len(body)) + kind + body
                + struct.pack(">I", zlib.crc32(kind + body)))

    ihdr = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", b"") + chunk(b"IEND", b"")


@pytest.mark.parametrize("edit,message", [
    (lambda d: d["bufferViews"][-2].pop("byteLength"), "not inside the binary chunk"),
    (lambda d: d["bufferViews"][-2].update(byteOffset=-64), "not inside the binary chunk"),
    (lambda d: d.update(textures=None), "no texture 0"),
    (lambda d: d["images"][0].pop("bufferView"), "only images in the .glb's binary"),
], ids=["no-byte-length", "negative-offset", "no-textures", "image-by-uri"])
def test_a_hostile_glb_is_refused_as_a_mesh_naming_its_texture(edit, message):
    """The mesh loader checks the film's textures (uploads and files alike): a 422's
    MeshError, never a crash, and a mesh without them is not read at all."""
    from opaline.scene.meshfile import MeshError, parse_mesh

    with pytest.raises(MeshError, match=message):
        parse_mesh(_edited(edit), ".glb")


def test_a_bomb_or_a_16_bit_texture(tmp_path):
    """A texture declaring more texels than allowed is refused before a pixel is decoded; a
    16-bit grey thickness texture keeps its precision instead of clipping to 8 bits."""
    # 5000² is under Pillow's own bomb limit: the refusal is the reader's, from the header
    # (the file holds no pixels, so a decode would fail otherwise).
    with pytest.raises(ValueError, match="5000×5000 texels, more than 16777216"):
        read_film_textures(other_tools_glb(thickness_png=_png_header(5000, 5000)))
    with pytest.raises(ValueError, match="not a readable image"):  # Pillow's bomb limit
        read_film_textures(other_tools_glb(thickness_png=_png_header(20000, 20000)))
    grey = (np.arange(64 * 48, dtype=np.uint32).reshape(48, 64) * 21).astype(np.uint16)
    out = io.BytesIO()
    Image.fromarray(grey).save(out, "PNG")
    field = read_film_textures(other_tools_glb(thickness_png=out.getvalue())).thickness
    np.testing.assert_allclose(field, grey / 65535.0, atol=1e-6)


def test_the_json_chunk_alone_says_whether_a_file_has_a_film(tmp_path):
    from opaline.scene.gltf_film import film_texture_names, texture_names

    path = tmp_path / "film.glb"
    path.write_bytes(other_tools_glb())
    assert film_texture_names(path) == {"iridescenceThicknessTexture", "iridescenceTexture"}
    assert texture_names(b"glTF" + bytes(8) + b"\xff\xff\xff\x7fJSON" + b"[" * 100000) == set()
