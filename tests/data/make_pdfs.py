#!/usr/bin/env python3
"""Makes the PDF test files of tests/vision/test_pdf.cpp. Run from tests/data:

    python3 make_pdfs.py

Writes bad/locked.pdf and bad/pages_5000.pdf (need qpdf), bad/page_14400pt.pdf, bad/truncated.pdf,
bad/empty.pdf, bad/text_named.pdf, bad/title_2000_bytes.pdf, documents/rotated_text.pdf,
documents/titled.pdf and documents/long_paragraph.pdf (with its text in long_paragraph.txt). See bad/IMAGES.md and SOURCES.md.
"""
import math
import os
import subprocess


def write_pdf(path, objects, info=None):
    """objects: list of bytes, object i+1 is objects[i]; object 1 is the catalog. info: the object number of
    the document information dictionary, or None."""
    out = bytearray(b"%PDF-1.4\n%\xe2\xe3\xcf\xd3\n")
    offsets = []
    for i, body in enumerate(objects):
        offsets.append(len(out))
        out += b"%d 0 obj\n" % (i + 1) + body + b"\nendobj\n"
    xref = len(out)
    out += b"xref\n0 %d\n0000000000 65535 f \n" % (len(objects) + 1)
    for off in offsets:
        out += b"%010d 00000 n \n" % off
    info_ref = b" /Info %d 0 R" % info if info else b""
    out += b"trailer\n<< /Size %d /Root 1 0 R%s >>\nstartxref\n%d\n%%%%EOF\n" % (len(objects) + 1, info_ref, xref)
    with open(path, "wb") as f:
        f.write(out)


def stream(data, extra=b""):
    return b"<< /Length %d %s>>\nstream\n" % (len(data), extra) + data + b"\nendstream"


def many_pages(path, n):
    """n pages in one flat page tree, all drawing the same content stream (object 3)."""
    content = b"0 0 0 RG 8 w 100 100 400 600 re S BT /F1 48 Tf 150 400 Td (Page) Tj ET"
    kids = b" ".join(b"%d 0 R" % (5 + i) for i in range(n))
    objects = [
        b"<< /Type /Catalog /Pages 2 0 R >>",
        b"<< /Type /Pages /Count %d /Kids [%s] /MediaBox [0 0 612 792] >>" % (n, kids),
        stream(content),
        b"<< /Type /Font /Subtype /Type1 /BaseFont /Helvetica >>",
    ]
    for _ in range(n):
        objects.append(b"<< /Type /Page /Parent 2 0 R /Contents 3 0 R /Resources << /Font << /F1 4 0 R >> >> >>")
    write_pdf(path, objects)


def circle(cx, cy, r):
    """A circle as four Bezier curves."""
    k = 0.5523 * r
    return (b"%.1f %.1f m " % (cx + r, cy)
            + b"%.1f %.1f %.1f %.1f %.1f %.1f c " % (cx + r, cy + k, cx + k, cy + r, cx, cy + r)
            + b"%.1f %.1f %.1f %.1f %.1f %.1f c " % (cx - k, cy + r, cx - r, cy + k, cx - r, cy)
            + b"%.1f %.1f %.1f %.1f %.1f %.1f c " % (cx - r, cy - k, cx - k, cy - r, cx, cy - r)
            + b"%.1f %.1f %.1f %.1f %.1f %.1f c h " % (cx + k, cy - r, cx + r, cy - k, cx + r, cy))


def huge_page(path):
    """One 14400 x 14400 pt page (the largest PDF 1.4 allows): a black ring 500 pt thick, radius 5000 pt."""
    content = b"0 0 0 RG 500 w " + circle(7200, 7200, 5000) + b"S"
    write_pdf(path, [
        b"<< /Type /Catalog /Pages 2 0 R >>",
        b"<< /Type /Pages /Count 1 /Kids [3 0 R] >>",
        b"<< /Type /Page /Parent 2 0 R /MediaBox [0 0 14400 14400] /Contents 4 0 R >>",
        stream(content),
    ])


def rotated_text(path):
    """A 400 x 300 pt media box, a crop box offset by (50, 20), /Rotate 90, and three words in 36 pt Helvetica
    (unrotated frame: "Top" near the crop box's top left, "Middle" in the middle, "Corner" near its bottom right)."""
    content = (b"BT /F1 36 Tf 70 250 Td (Top) Tj ET "
               b"BT /F1 36 Tf 160 150 Td (Middle) Tj ET "
               b"BT /F1 36 Tf 250 40 Td (Corner) Tj ET")
    write_pdf(path, [
        b"<< /Type /Catalog /Pages 2 0 R >>",
        b"<< /Type /Pages /Count 1 /Kids [3 0 R] >>",
        b"<< /Type /Page /Parent 2 0 R /MediaBox [0 0 400 300] /CropBox [50 20 400 300] /Rotate 90"
        b" /Contents 4 0 R /Resources << /Font << /F1 5 0 R >> >> >>",
        stream(content),
        b"<< /Type /Font /Subtype /Type1 /BaseFont /Helvetica >>",
    ])


def titled(path, title):
    """One 300 x 200 pt page with a ring drawn on it, and a document information dictionary whose /Title is
    `title` (a str), written as UTF-16BE with its byte-order mark (PDF text strings may be UTF-16)."""
    hexed = ("FEFF" + title.encode("utf-16-be").hex().upper()).encode()
    write_pdf(path, [
        b"<< /Type /Catalog /Pages 2 0 R >>",
        b"<< /Type /Pages /Count 1 /Kids [3 0 R] >>",
        b"<< /Type /Page /Parent 2 0 R /MediaBox [0 0 300 200] /Contents 4 0 R >>",
        stream(b"0 0 0 RG 6 w " + circle(150, 100, 60) + b"S"),
        b"<< /Title <" + hexed + b"> /Producer (haptic-kiosk make_pdfs.py) >>",
    ], info=5)


def long_paragraph_text():
    """About 9 KB of plain English in sentences, the words a test expects to hear in order."""
    words = []
    i = 0
    while len(" ".join(words)) < 9000:
        i += 1
        words += ("Sentence %d of this long paragraph tells the visitor how the kiosk reads a page aloud, "
                  "one piece after another, so that no word is lost." % i).split()
    return " ".join(words)


def long_paragraph(path):
    """One letter-size page holding one paragraph of ~9 KB (long_paragraph_text) in 7 pt Helvetica, 8.5 pt
    apart, 150 characters a line: one text block, as a dense page of a manual gives."""
    lines, line = [], ""
    for w in long_paragraph_text().split():
        if len(line) + 1 + len(w) > 150:
            lines.append(line)
            line = w
        else:
            line = (line + " " + w).strip()
    lines.append(line)
    ops = [b"BT /F1 7 Tf 8.5 TL 40 760 Td"]
    for ln in lines:
        ops.append(b"(" + ln.encode("ascii") + b") '")
    ops.append(b"ET")
    write_pdf(path, [
        b"<< /Type /Catalog /Pages 2 0 R >>",
        b"<< /Type /Pages /Count 1 /Kids [3 0 R] >>",
        b"<< /Type /Page /Parent 2 0 R /MediaBox [0 0 612 792] /Contents 4 0 R /Resources << /Font << /F1 5 0 R >> >> >>",
        stream(b" ".join(ops)),
        b"<< /Type /Font /Subtype /Type1 /BaseFont /Helvetica >>",
    ])
    with open(os.path.splitext(path)[0] + ".txt", "w") as f:
        f.write(long_paragraph_text() + "\n")


def main():
    os.makedirs("bad", exist_ok=True)
    subprocess.run(["qpdf", "--encrypt", "user", "owner", "256", "--", "documents/horse_and_page.pdf", "bad/locked.pdf"], check=True)
    many_pages("bad/pages_5000.raw.pdf", 5000)  # 650 KB of page objects; qpdf packs them into object streams
    subprocess.run(["qpdf", "--object-streams=generate", "--compress-streams=y", "bad/pages_5000.raw.pdf", "bad/pages_5000.pdf"], check=True)
    os.remove("bad/pages_5000.raw.pdf")
    huge_page("bad/page_14400pt.pdf")
    with open("documents/shared-mime-info-spec.pdf", "rb") as f:
        spec = f.read()
    with open("bad/truncated.pdf", "wb") as f:
        f.write(spec[: len(spec) // 2])
    open("bad/empty.pdf", "wb").close()
    with open("bad/text_named.pdf", "w") as f:
        f.write("This is a plain text file with a .pdf name, not a PDF.\n")
    rotated_text("documents/rotated_text.pdf")
    titled("documents/titled.pdf", "A ring, drawn for the hand \u2014 caf\u00e9 edition")
    long_paragraph("documents/long_paragraph.pdf")
    titled("bad/title_2000_bytes.pdf", "x" * 2000)


if __name__ == "__main__":
    main()
