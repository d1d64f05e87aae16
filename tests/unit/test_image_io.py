"""Tests for geomlib.image_io: 8-bit images through Pillow, 16-bit colour PNGs through VTK.

Expected values are written out by hand, or come from an independent codec (Pillow, or the
straightforward PNG encoder below written from the PNG specification).
"""

from __future__ import annotations

import struct
import zlib

import numpy as np
import pytest
from PIL import Image

from geomlib import image_io as io
from geomlib.validate import MeshError


def write(tmp_path, name, content):
    p = tmp_path / name
    p.write_bytes(content.encode() if isinstance(content, str) else content)
    return p


# --------------------------------------------------------------------------------------------
# Images
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("dtype", [np.uint8, np.uint16])
@pytest.mark.parametrize("shape", [(5, 7), (5, 7, 2), (5, 7, 3), (5, 7, 4)])
def test_png_round_trip_is_exact(tmp_path, dtype, shape):
    img = np.random.default_rng(6).integers(0, np.iinfo(dtype).max + 1, size=shape).astype(dtype)
    io.write_image(tmp_path / "i.png", img)
    out = io.read_image(tmp_path / "i.png")
    assert out.dtype == dtype and out.shape == shape
    np.testing.assert_array_equal(out, img)


def test_16_bit_pngs_we_write_are_valid_for_pillow(tmp_path):
    img = np.random.default_rng(7).integers(0, 65536, size=(6, 9, 3)).astype(np.uint16)
    io.write_image(tmp_path / "rgb16.png", img)
    with Image.open(tmp_path / "rgb16.png") as im:
        assert im.size == (9, 6)
        np.testing.assert_array_equal(np.asarray(im), img >> 8)  # Pillow keeps the high byte
    io.write_image(tmp_path / "g16.png", img[:, :, 0])
    with Image.open(tmp_path / "g16.png") as im:
        np.testing.assert_array_equal(np.asarray(im), img[:, :, 0])


def png_encode_reference(img16, filters):
    """Straightforward PNG encoder for 16-bit RGB with a chosen filter per row (PNG spec, sec. 9)."""
    h, w, _ = img16.shape
    raw = img16.astype(">u2").tobytes()
    stride, bpp = w * 6, 6
    out, prev = bytearray(), bytes(stride)
    for y in range(h):
        row = raw[y * stride : (y + 1) * stride]
        f = filters[y]
        out.append(f)
        for x in range(stride):
            a = row[x - bpp] if x >= bpp else 0
            b = prev[x]
            c = prev[x - bpp] if x >= bpp else 0
            p = a + b - c
            pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
            paeth = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
            pred = [0, a, b, (a + b) // 2, paeth][f]
            out.append((row[x] - pred) % 256)
        prev = row

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    ihdr = struct.pack(">IIBBBBB", w, h, 16, 2, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(bytes(out))) + chunk(b"IEND", b"")


@pytest.mark.parametrize("filters", [[0] * 5, [1, 2, 1, 2, 0], [3] * 5, [4] * 5, [0, 1, 2, 3, 4]])
def test_16_bit_png_reader_undoes_every_filter(tmp_path, filters):
    img = np.random.default_rng(8).integers(0, 65536, size=(5, 4, 3)).astype(np.uint16)
    img[2] = img[1]  # repeated rows and smooth parts exercise different predictor branches
    img[:, 2] = img[:, 1] + 1
    path = write(tmp_path, "f.png", png_encode_reference(img, filters))
    np.testing.assert_array_equal(io.read_image(path), img)


def test_float_images_need_bits(tmp_path):
    img = np.linspace(0, 1, 12).reshape(3, 4)
    with pytest.raises(MeshError, match="pass bits=8 or bits=16"):
        io.write_image(tmp_path / "f.png", img)
    io.write_image(tmp_path / "f8.png", img, bits=8)
    np.testing.assert_array_equal(io.read_image(tmp_path / "f8.png"), np.round(img * 255).astype(np.uint8))
    io.write_image(tmp_path / "f16.png", np.dstack([img] * 3), bits=16)
    out = io.read_image(tmp_path / "f16.png", as_float=True)
    np.testing.assert_allclose(out, np.dstack([img] * 3), atol=0.5 / 65535)
    with pytest.raises(MeshError, match=r"value 1\.5 at pixel \(0, 0\) is outside \[0, 1\]"):
        io.write_image(tmp_path / "f.png", img + 1.5 * (img == 0), bits=8)


def test_write_image_rejects_bad_shapes_and_types(tmp_path):
    p = tmp_path / "x.png"
    with pytest.raises(MeshError, match=r"img has shape \(4,\)"):
        io.write_image(p, np.zeros(4, np.uint8))
    with pytest.raises(MeshError, match="img has 5 channel"):
        io.write_image(p, np.zeros((2, 2, 5), np.uint8))
    with pytest.raises(MeshError, match="img has dtype int64; convert it to uint8 or uint16"):
        io.write_image(p, np.zeros((2, 2), np.int64))
    with pytest.raises(MeshError, match="does not fit 8 bits"):
        io.write_image(p, np.full((2, 2), 300), bits=8)
    with pytest.raises(MeshError, match="16-bit images can only be written as .png"):
        io.write_image(tmp_path / "x.jpg", np.zeros((2, 2), np.uint16))
    with pytest.raises(MeshError, match="img is uint8 but bits=16"):
        io.write_image(p, np.zeros((2, 2), np.uint8), bits=16)
    io.write_image(p, np.full((2, 3), 200), bits=8)  # plain ints are fine once bits says how
    assert io.read_image(p).tolist() == [[200] * 3] * 2


def test_read_image_via_pillow_formats(tmp_path):
    rgb = np.random.default_rng(9).integers(0, 256, size=(4, 6, 3)).astype(np.uint8)
    io.write_image(tmp_path / "x.bmp", rgb)
    np.testing.assert_array_equal(io.read_image(tmp_path / "x.bmp"), rgb)
    Image.fromarray(rgb).convert("P").save(tmp_path / "pal.png")  # palette image comes back as RGB
    assert io.read_image(tmp_path / "pal.png").shape == (4, 6, 3)
    with pytest.raises(MeshError, match="not an image file"):
        io.read_image(write(tmp_path, "junk.png", b"definitely not a png"))


def test_truncated_16_bit_png_is_a_clear_error_not_a_crash(tmp_path):
    img = np.random.default_rng(11).integers(0, 65536, size=(20, 30, 3)).astype(np.uint16)
    io.write_image(tmp_path / "ok.png", img)
    data = (tmp_path / "ok.png").read_bytes()
    with pytest.raises(MeshError, match=r"read_image: .*cut\.png: PNG is truncated"):
        io.read_image(write(tmp_path, "cut.png", data[: len(data) // 2]))


def test_folder_and_missing_output_folder(tmp_path):
    with pytest.raises(MeshError, match="is a folder; give an image file"):
        io.read_image(tmp_path)
    with pytest.raises(MeshError, match=r"the folder .*nope does not exist; create it first"):
        io.write_image(tmp_path / "nope" / "x.png", np.zeros((2, 2), np.uint8))
    assert not (tmp_path / "nope").exists()
