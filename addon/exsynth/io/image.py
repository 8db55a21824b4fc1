# SPDX-License-Identifier: GPL-3.0-or-later
"""Blender images <-> numpy (H, W, C) float32, and the colour encodings they carry.

Orientation: Blender stores pixels bottom row first; the synthesis engine
takes exemplars top row first (as the image is seen), so `exemplar_pixels`
flips them. Baked images come back from the engine bottom row first (row 0
at v = 0), which is Blender's order already.

Encoding: what the numbers in a pixel mean, so that results are stored as
the exemplar's were.
- "srgb": an 8-bit colour image; `pixels` gives its display-encoded values,
  and an 8-bit result image with the same colour space shows them as they are.
- "linear": a float image (EXR, HDR, 16-bit PNG/TIFF, which Blender converts
  to scene-linear floats on load).
- "data": either kind marked Non-Color (roughness, height, normals): values
  are used as they are and never converted.
"""

import os

import bpy
import numpy as np

from ..jobs import InputError

SRGB, LINEAR, DATA = "srgb", "linear", "data"


def encoding_of(image):
    if image.colorspace_settings.is_data:
        return DATA
    return LINEAR if image.is_float else SRGB


def exemplar_pixels(image, use_alpha=False, role="exemplar"):
    """(H, W, 3) float32 RGB, or RGBA with `use_alpha`, row 0 the top row.

    Grey images become RGB (the engine needs the same channels in every
    view). Images without alpha get alpha 1. `role` names the input in errors.
    """
    if image is None:
        raise InputError(f"no {role} image chosen")
    width, height = image.size  # asking for the size loads the file if needed
    channels = image.channels
    if width == 0 or height == 0 or channels == 0:
        where = f" (file '{bpy.path.abspath(image.filepath)}')" if image.filepath else ""
        raise InputError(
            f"the {role} image '{image.name}' has no pixels{where}. Fix the path and reload it "
            "(Image Editor > Image > Reload) or pick another image"
        )
    flat = np.empty(width * height * channels, np.float32)
    image.pixels.foreach_get(flat)
    px = flat.reshape(height, width, channels)[::-1]
    if channels >= 3:
        rgb = px[..., :3]
    else:  # grey or grey + alpha
        rgb = np.repeat(px[..., :1], 3, axis=2)
    if not use_alpha:
        out = rgb
    else:
        alpha = px[..., channels - 1:] if channels in (2, 4) else np.ones_like(px[..., :1])
        out = np.concatenate([rgb, alpha], axis=2)
    out = np.ascontiguousarray(out, np.float32)
    if not np.all(np.isfinite(out)):
        raise InputError(
            f"the {role} image '{image.name}' has NaN or infinite pixels. Fix or replace them "
            "(e.g. clamp in the Compositor and save a copy) or pick another image"
        )
    return out


def convert(values, from_encoding, to_encoding):
    """Re-encode colour channels (the first three) between "srgb" and "linear";
    "data" and equal encodings are left as they are."""
    if from_encoding == to_encoding or DATA in (from_encoding, to_encoding):
        return values
    out = np.array(values, np.float32, copy=True)
    f = srgb_to_linear if from_encoding == SRGB else linear_to_srgb
    out[..., :3] = f(out[..., :3])
    return out


def srgb_to_linear(v):
    v = np.asarray(v, np.float32)
    curve = ((np.maximum(v, 0.04045) + 0.055) / 1.055) ** 2.4
    return np.where(v <= 0.04045, v / 12.92, curve).astype(np.float32)


def linear_to_srgb(v):
    v = np.asarray(v, np.float32)
    curve = 1.055 * np.maximum(v, 0.0031308) ** (1 / 2.4) - 0.055
    return np.where(v <= 0.0031308, v * 12.92, curve).astype(np.float32)


def new_image(name, pixels, encoding, created=None, pack=True):
    """A new image from (H, W, C) float32 pixels, row 0 at the bottom (Blender's order).

    "srgb" makes an 8-bit sRGB image, "linear" a float one, "data" a float
    Non-Color one (values kept exactly). C is 1..4; missing colour channels repeat the first,
    missing alpha is 1. Packed into the .blend, so the result survives a save.
    """
    pixels = np.asarray(pixels, np.float32)
    if pixels.ndim == 2:
        pixels = pixels[..., None]
    height, width, channels = pixels.shape
    image = bpy.data.images.new(name, width, height, alpha=channels in (2, 4),
                                float_buffer=encoding != SRGB)
    if created is not None:
        created.add(image)
    if encoding == DATA:
        image.colorspace_settings.name = "Non-Color"
    image.pixels.foreach_set(to_rgba(pixels).ravel())
    image.update()
    if pack:
        image.pack()
    return image


def to_rgba(pixels):
    """(H, W, C) -> (H, W, 4) float32."""
    height, width, channels = pixels.shape
    rgba = np.ones((height, width, 4), np.float32)
    if channels >= 3:
        rgba[..., :3] = pixels[..., :3]
    else:
        rgba[..., :3] = pixels[..., :1]
    if channels in (2, 4):
        rgba[..., 3] = pixels[..., channels - 1]
    return rgba


# ---- files (the CLI) -----------------------------------------------------------------
def load(path):
    """Open an image file through Blender (any format it reads); OSError if it cannot."""
    try:
        image = bpy.data.images.load(os.path.abspath(path), check_existing=False)
    except RuntimeError as exc:
        raise OSError(f"Blender could not read the image {path}: {exc}") from None
    if image.size[0] == 0 or image.size[1] == 0:
        bpy.data.images.remove(image)
        raise OSError(f"Blender could not read the image {path}: no pixels")
    return image


def save_png(path, pixels, encoding, name="exsynth_out"):
    """Write (H, W, C) float32 pixels (row 0 at the bottom) as a PNG through Blender:
    8-bit, alpha kept when C is 2 or 4. A float ("linear") result is converted
    to sRGB by Blender's colour management, as when saving from the Image Editor."""
    image = new_image(name, pixels, encoding, pack=False)
    try:
        image.filepath_raw = os.path.abspath(path)
        image.file_format = 'PNG'
        image.save()
    finally:
        bpy.data.images.remove(image)
