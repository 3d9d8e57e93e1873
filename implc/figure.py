"""A grid of labelled image tiles (the benchmark's figure, laid out like the paper's Fig. 2).

Pillow only: the figure is a picture of renders with a caption per tile, so a plotting
library would add a dependency and nothing a reader needs.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
from PIL import Image, ImageDraw, ImageFont

BACKGROUND = (255, 255, 255)
TEXT = (20, 20, 20)
MISSING = (200, 200, 200)
MAX_FONT_SIZE = 15  # captions of 256-pixel tiles; smaller tiles get a smaller font
GAP = 6  # pixels between tiles


def tile_image(color: np.ndarray, tile: int) -> Image.Image:
    """An 8-bit thumbnail of a float colour image in [0, 1], longest side `tile` pixels.

    Box filtering averages the pixels a thumbnail pixel covers, so a one-pixel false-root
    line stays visible (fainter) instead of disappearing between resampled pixels.
    """
    rgb = np.round(np.clip(color, 0.0, 1.0) * 255.0).astype(np.uint8)
    image = Image.fromarray(rgb, mode="RGB")
    height, width = rgb.shape[:2]
    scale = min(1.0, tile / max(width, height))
    size = (max(1, round(width * scale)), max(1, round(height * scale)))
    return image if size == (width, height) else image.resize(size, Image.Resampling.BOX)


def grid_figure(
    rows: Sequence[str],
    columns: Sequence[str],
    tiles: Mapping[tuple[str, str], Image.Image],
    captions: Mapping[tuple[str, str], Sequence[str]],
    title: str = "",
    row_labels: Mapping[str, str] | None = None,
) -> Image.Image:
    """Tiles at (row, column) with caption lines above each, row labels on the left.

    A missing tile is drawn as a grey box so the grid keeps its shape.
    """
    tile_w = max((im.width for im in tiles.values()), default=64)
    tile_h = max((im.height for im in tiles.values()), default=64)
    font_size = max(9, min(MAX_FONT_SIZE, tile_w // 16))
    font = _font(font_size)
    line_height = font_size + font_size // 3 + 1
    caption_lines = max((len(c) for c in captions.values()), default=0)
    caption_h = caption_lines * line_height + 4
    labels = {r: (row_labels or {}).get(r, r) for r in rows}
    measure = ImageDraw.Draw(Image.new("RGB", (1, 1)))
    label_w = max((measure.textlength(text, font=font) for text in labels.values()), default=0)
    left = int(label_w) + 2 * GAP
    top = (line_height + GAP) if title else GAP
    cell_w, cell_h = tile_w + GAP, caption_h + tile_h + GAP
    width = left + len(columns) * cell_w + GAP
    height = top + len(rows) * cell_h + GAP
    figure = Image.new("RGB", (width, height), BACKGROUND)
    draw = ImageDraw.Draw(figure)
    if title:
        draw.text((GAP, GAP // 2), title, fill=TEXT, font=font)
    for r, row in enumerate(rows):
        y = top + r * cell_h
        draw.text((GAP, y + caption_h + tile_h // 2 - line_height // 2), labels[row],
                  fill=TEXT, font=font)
        for c, column in enumerate(columns):
            x = left + c * cell_w
            for k, line in enumerate(captions.get((row, column), ())):
                draw.text((x, y + k * line_height), line, fill=TEXT, font=font)
            image = tiles.get((row, column))
            if image is None:
                draw.rectangle((x, y + caption_h, x + tile_w - 1, y + caption_h + tile_h - 1),
                               fill=MISSING)
            else:
                figure.paste(image, (x, y + caption_h))
    return figure


def _font(size: int) -> ImageFont.ImageFont | ImageFont.FreeTypeFont:
    """Pillow's bundled font at `size` (needs FreeType; else its small bitmap font)."""
    try:
        return ImageFont.load_default(size=size)
    except (TypeError, OSError):  # Pillow < 10.1 or no FreeType
        return ImageFont.load_default()
