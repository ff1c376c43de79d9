#!/usr/bin/env python3
"""Contact sheet: every test picture's overlay (summary.json's picture with the scene's curves drawn
on it, explore's overlay.png) before and after, side by side, in one PNG a person can judge at a glance.

Usage: contact_sheet.py WORK OUT.png   where WORK/canny/NAME and WORK/auto/NAME are explore output folders
(bench/scene_detectors.sh makes them: "before" = the old pipeline (canny, no gap closing, no shape budget), "after" = the defaults)."""
import json
import os
import sys

from PIL import Image, ImageDraw

TILE_W, TILE_H, LABEL_H, PAIRS_PER_ROW, GAP = 260, 190, 18, 2, 8


def tile(folder):
    """The overlay of one explore run, fitted into TILE_W x TILE_H, with its shape count and closed share."""
    im = Image.open(os.path.join(folder, "overlay.png")).convert("RGB")
    im.thumbnail((TILE_W, TILE_H))
    curves = json.load(open(os.path.join(folder, "scene.json")))["curves"]
    closed = sum(c["closed"] for c in curves)
    return im, f"{len(curves)} shapes, {closed} closed"


def main(work, out):
    names = sorted(os.listdir(os.path.join(work, "auto")))
    rows = (len(names) + PAIRS_PER_ROW - 1) // PAIRS_PER_ROW
    cell_w, cell_h = 2 * TILE_W + GAP, TILE_H + 2 * LABEL_H
    sheet = Image.new("RGB", (PAIRS_PER_ROW * (cell_w + 3 * GAP), rows * (cell_h + GAP) + LABEL_H), "white")
    draw = ImageDraw.Draw(sheet)
    draw.text((GAP, 2), "each picture: before (Canny, no gap closing, no shape budget) | after (the defaults)", fill="black")
    for k, name in enumerate(names):
        x0 = (k % PAIRS_PER_ROW) * (cell_w + 3 * GAP) + GAP
        y0 = (k // PAIRS_PER_ROW) * (cell_h + GAP) + LABEL_H
        draw.text((x0, y0), name, fill="black")
        for j, mode in enumerate(("canny", "auto")):
            im, label = tile(os.path.join(work, mode, name))
            x = x0 + j * (TILE_W + GAP)
            sheet.paste(im, (x, y0 + LABEL_H))
            draw.text((x, y0 + LABEL_H + TILE_H + 2), ("before: " if j == 0 else "after: ") + label, fill="black")
    sheet.save(out, optimize=True)
    print(f"contact sheet: {out} ({len(names)} pictures)")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
