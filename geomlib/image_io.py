"""Image files through Pillow; 16-bit PNGs with colour or alpha written by VTK, read by our decoder.

Pillow reads and writes every common format, but reduces 16-bit RGB/RGBA (and grey + alpha)
PNGs to 8 bits. Those are written by VTK's ``vtkPNGWriter`` (VTK comes with pyvista, already a
dependency) and read by the small decoder here (zlib + PNG row filters, vectorised): VTK's
``vtkPNGReader`` would do it, but it crashes the interpreter on a truncated file, and the reader
must fail with a clear error instead (the VDM lab's preview is the one such file). Float maps at full precision are saved with ``np.save``/
``np.savez`` directly. Mesh files are in :mod:`geomlib.mesh_io`.

Examples
--------
>>> import numpy as np, tempfile, os
>>> from geomlib.image_io import read_image, write_image
>>> path = os.path.join(tempfile.mkdtemp(), "ramp.png")
>>> write_image(path, np.linspace(0, 1, 12).reshape(3, 4), bits=16)
>>> read_image(path).dtype
dtype('uint16')
"""

from __future__ import annotations

import os
import struct
import zlib
from pathlib import Path

import numpy as np

from geomlib.mesh_io import check_regular_file
from geomlib.validate import MeshError, as_array, as_image

__all__ = ["read_image", "write_image"]

PathLike = str | os.PathLike

_PNG_SIG = b"\x89PNG\r\n\x1a\n"
_PNG_CHANNELS = {0: 1, 2: 3, 4: 2, 6: 4}  # PNG colour type -> channels


def read_image(path: PathLike, *, as_float: bool = False) -> np.ndarray:
    """Read an image file into an array.

    Parameters
    ----------
    path : str or path-like
        Any format Pillow reads (PNG, JPEG, BMP, TGA, TIFF, ...). 16-bit PNGs keep all 16 bits,
        including RGB and RGBA ones (which Pillow alone would reduce to 8 bits).
    as_float : bool
        Return float64 values scaled to [0, 1] (by 255 or 65535) instead of integers.

    Returns
    -------
    image : (h, w) or (h, w, c) ndarray
        uint8 for 8-bit files, uint16 for 16-bit files; ``c`` is 2 (grey + alpha), 3 (RGB) or
        4 (RGBA). Palette images become RGB (RGBA if they have transparency); 32-bit float TIFFs
        come back as float32.

    Raises
    ------
    FileNotFoundError
        The file does not exist.
    MeshError
        The file is not a readable image.
    """
    where = "read_image"
    check_regular_file(path, where, "an image file")
    with open(path, "rb") as fh:
        head = fh.read(33)
    if head[:8] == _PNG_SIG and len(head) >= 33 and head[12:16] == b"IHDR":
        depth, ctype = head[24], head[25]
        if depth == 16 and ctype in (2, 4, 6):
            img = _read_png16(path, where)
            return img / 65535.0 if as_float else img
    from PIL import Image, UnidentifiedImageError

    try:
        with Image.open(path) as im:
            im.load()
            mode = im.mode
            if mode == "P":
                im = im.convert("RGBA" if "transparency" in im.info else "RGB")
            elif mode == "PA":
                im = im.convert("RGBA")
            elif mode == "1":
                im = im.convert("L")
            elif mode in ("CMYK", "YCbCr", "LAB", "HSV", "RGBX"):
                im = im.convert("RGB")
            elif mode == "La":
                im = im.convert("LA")
            elif mode == "RGBa":
                im = im.convert("RGBA")
            a = np.array(im)
    except UnidentifiedImageError:
        raise MeshError(f"{where}: {path}: not an image file Pillow can read") from None
    except (OSError, SyntaxError, ValueError) as e:
        if isinstance(e, FileNotFoundError):
            raise
        raise MeshError(f"{where}: {path}: cannot read the image ({e})") from None
    if a.dtype.kind in "iu" and a.dtype != np.uint8:
        if a.size and a.min() >= 0 and a.max() <= 65535:
            a = a.astype(np.uint16)
        bits = 16
    else:
        bits = 8
    if as_float:
        if a.dtype.kind == "f":
            return a.astype(np.float64)
        return a / (255.0 if bits == 8 else 65535.0)
    return a


def write_image(path: PathLike, img, *, bits: int | None = None) -> None:
    """Write an image: 8-bit via Pillow (any format), 16-bit as PNG.

    Parameters
    ----------
    path : str or path-like
        Output file; the extension picks the format. 16-bit images need ``.png``.
    img : (h, w) or (h, w, c) array_like, c in 1..4
        uint8 (8-bit) or uint16 (16-bit) values written as they are; ``c`` = 2 is grey + alpha,
        3 RGB, 4 RGBA. Float images (values in [0, 1]) need ``bits``. Other integer dtypes
        need ``bits`` too and must fit its range.
    bits : {8, 16}, optional
        Bit depth to write. For float images values are quantised with
        ``round(x * (2**bits - 1))``; for integer images the values must already fit.

    Raises
    ------
    MeshError
        Wrong shape, unsupported dtype, float image without ``bits``, values out of range,
        or 16-bit requested for a format other than PNG.
    """
    where = "write_image"
    a = as_image(img, "img", channels=(1, 2, 3, 4), where=where)
    if a.ndim == 3 and a.shape[2] == 1:
        a = a[:, :, 0]
    if bits is not None and bits not in (8, 16):
        raise MeshError(f"{where}: bits must be 8 or 16, got {bits!r}")
    kind = a.dtype.kind
    if kind == "b":
        a = a.astype(np.uint8) * 255
        kind = "u"
    if kind == "f":
        if bits is None:
            raise MeshError(
                f"{where}: img has dtype {a.dtype} (float); pass bits=8 or bits=16 to quantise values in [0, 1], "
                f"or convert it to uint8/uint16 yourself"
            )
        a = as_array(a, "img", dtype=np.float64, where=where)
        out_of = (a < 0) | (a > 1)
        if out_of.any():
            p = tuple(int(i) for i in np.argwhere(out_of)[0])
            raise MeshError(
                f"{where}: img value {a[p]:.6g} at pixel {p[:2]} is outside [0, 1]; clip or rescale before writing"
            )
        a = np.round(a * (2**bits - 1)).astype(np.uint8 if bits == 8 else np.uint16)
    elif kind in "iu":
        native = {np.dtype(np.uint8): 8, np.dtype(np.uint16): 16}.get(a.dtype)
        if bits is None:
            if native is None:
                raise MeshError(f"{where}: img has dtype {a.dtype}; convert it to uint8 or uint16, or pass bits=8|16")
            bits = native
        elif native is not None and native != bits:
            raise MeshError(
                f"{where}: img is {a.dtype} but bits={bits}; convert the values yourself (no implicit rescaling)"
            )
        hi = 2**bits - 1
        if a.size and (a.min() < 0 or a.max() > hi):
            p = tuple(int(i) for i in np.argwhere((a < 0) | (a > hi))[0])
            raise MeshError(f"{where}: img value {a[p]} at pixel {p[:2]} does not fit {bits} bits (0..{hi})")
        a = a.astype(np.uint8 if bits == 8 else np.uint16)
    else:
        raise MeshError(f"{where}: img has dtype {a.dtype}; expected uint8, uint16 or float")

    parent = Path(path).parent
    if not parent.is_dir():
        raise MeshError(f"{where}: {path}: the folder {parent} does not exist; create it first")
    if a.dtype == np.uint16:
        if Path(path).suffix.lower() != ".png":
            raise MeshError(f"{where}: {path}: 16-bit images can only be written as .png")
        if a.ndim == 2:  # grey: Pillow keeps 16 bits
            from PIL import Image

            Image.fromarray(np.ascontiguousarray(a)).save(path)
        else:
            _write_png16(path, a, where)
        return
    from PIL import Image

    try:
        Image.fromarray(np.ascontiguousarray(a)).save(path)
    except (ValueError, OSError, KeyError) as e:
        c = 1 if a.ndim == 2 else a.shape[2]
        raise MeshError(f"{where}: {path}: cannot write a {c}-channel 8-bit image in this format ({e})") from None


def _write_png16(path: PathLike, a: np.ndarray, where: str) -> None:
    """A 16-bit PNG with 2, 3 or 4 channels, written by VTK (row 0 of ``a`` at the top)."""
    from vtkmodules.util.numpy_support import numpy_to_vtk
    from vtkmodules.vtkCommonDataModel import vtkImageData
    from vtkmodules.vtkIOImage import vtkPNGWriter

    h, w, c = a.shape
    img = vtkImageData()
    img.SetDimensions(w, h, 1)
    img.GetPointData().SetScalars(numpy_to_vtk(np.ascontiguousarray(a[::-1]).reshape(-1, c), deep=True))
    writer = vtkPNGWriter()
    writer.SetFileName(str(path))
    writer.SetInputData(img)
    writer.Write()
    if writer.GetErrorCode() or not Path(path).is_file():
        raise MeshError(f"{where}: {path}: could not write the PNG (VTK error code {writer.GetErrorCode()})")


def _read_png16(path: PathLike, where: str) -> np.ndarray:
    """Decode a non-interlaced 16-bit PNG (grey, grey+alpha, RGB or RGBA) to uint16.

    Our own decoder: Pillow reduces these to 8 bits, and VTK's reader crashes the interpreter
    (segmentation fault in libpng's error handler) on a truncated file.
    """
    with open(path, "rb") as fh:
        data = fh.read()

    def error(msg: str) -> MeshError:
        return MeshError(f"{where}: {path}: {msg}")

    pos, ihdr, idat = 8, None, []
    while pos + 8 <= len(data):
        length, kind = struct.unpack(">I4s", data[pos : pos + 8])
        payload = data[pos + 8 : pos + 8 + length]
        if len(payload) < length:
            raise error(f"PNG is truncated (chunk {kind.decode('latin-1')} at byte {pos})")
        if kind == b"IHDR":
            ihdr = payload
        elif kind == b"IDAT":
            idat.append(payload)
        elif kind == b"IEND":
            break
        pos += 12 + length
    if ihdr is None or not idat:
        raise error("PNG has no image data (IHDR/IDAT chunks missing)")
    w, h, depth, ctype, _, _, interlace = struct.unpack(">IIBBBBB", ihdr)
    if depth != 16 or ctype not in _PNG_CHANNELS:
        raise error(f"unsupported PNG layout (bit depth {depth}, colour type {ctype})")
    if interlace:
        raise error("interlaced 16-bit colour PNGs are not supported; save it without interlacing")
    c = _PNG_CHANNELS[ctype]
    bpp = 2 * c
    stride = w * bpp
    try:
        raw = zlib.decompress(b"".join(idat))
    except zlib.error as e:
        raise error(f"PNG image data is corrupt ({e})") from None
    if len(raw) < h * (stride + 1):
        raise error(f"PNG is truncated: image data holds {len(raw)} of {h * (stride + 1)} bytes")
    rows = np.frombuffer(raw, dtype=np.uint8, count=h * (stride + 1)).reshape(h, stride + 1)
    ftype = rows[:, 0]
    if ftype.max(initial=0) > 4:
        y = int(np.flatnonzero(ftype > 4)[0])
        raise error(f"PNG row {y} has an invalid filter type {int(ftype[y])}")
    R = _png_unfilter(rows[:, 1:].reshape(h, w, bpp), ftype)
    img = R.reshape(h, stride).view(">u2").reshape(h, w, c).astype(np.uint16)
    return img[:, :, 0] if c == 1 else img


def _png_unfilter(Fb: np.ndarray, ftype: np.ndarray) -> np.ndarray:
    """Undo PNG row filters on ``(h, w, bpp)`` bytes; vectorised over whole rows or anti-diagonals."""
    h, w, bpp = Fb.shape
    if (ftype == 0).all():
        return Fb
    if (ftype <= 2).all():
        R = np.empty_like(Fb)
        prev = np.zeros((w, bpp), np.uint8)
        for y in range(h):
            row = Fb[y]
            if ftype[y] == 1:
                row = np.cumsum(row, axis=0, dtype=np.uint8)  # wraps mod 256
            elif ftype[y] == 2:
                row = row + prev
            R[y] = row
            prev = R[y]
        return R
    # Average/Paeth depend on the left, upper and upper-left pixels, so pixels on one
    # anti-diagonal are independent: sweep the h + w - 1 diagonals.
    Fi = Fb.astype(np.int32)
    R = np.zeros((h + 1, w + 1, bpp), np.int32)  # zero row/column = the PNG "outside" bytes
    t = ftype.astype(np.int32)
    for d in range(h + w - 1):
        ys = np.arange(max(0, d - w + 1), min(h - 1, d) + 1)
        xs = d - ys
        a, b, cc = R[ys + 1, xs], R[ys, xs + 1], R[ys, xs]
        p = a + b - cc
        pa, pb, pc = np.abs(p - a), np.abs(p - b), np.abs(p - cc)
        paeth = np.where((pa <= pb) & (pa <= pc), a, np.where(pb <= pc, b, cc))
        tt = t[ys][:, None]
        pred = np.select([tt == 0, tt == 1, tt == 2, tt == 3], [0, a, b, (a + b) // 2], paeth)
        R[ys + 1, xs + 1] = (Fi[ys, xs] + pred) & 255
    return R[1:, 1:].astype(np.uint8)
