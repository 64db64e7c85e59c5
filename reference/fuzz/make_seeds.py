"""Write the fuzz seed corpus: small .hdr files, good and broken.

Usage: python3 make_seeds.py OUT_DIR   (stdlib only; `make -C reference/fuzz seeds`)

The files are written byte by byte here, independently of the reader under
test, so each seed is what its name says: flat, new-style RLE, old-style RLE,
each of the eight orientations, vertical crosses, and broken files.
"""
import random
import sys
from pathlib import Path

HEADER = b"#?RADIANCE\n# fuzz seed\nFORMAT=32-bit_rle_rgbe\nEXPOSURE=1.0\n\n"


def pixels(n, rng, runs=False):
    """n RGBE pixels (bytes of 4) with mantissas >= 3, so none looks like an RLE marker."""
    out, last = [], None
    for _ in range(n):
        if runs and last is not None and rng.random() < 0.6:
            out.append(last)
            continue
        e = rng.randrange(120, 140)
        last = bytes([rng.randrange(128, 256), rng.randrange(3, 256), rng.randrange(3, 256), e])
        out.append(last)
    return out


def flat(resolution, px):
    return HEADER + resolution + b"\n" + b"".join(px)


def rle_channel(data):
    """New-style RLE of one channel: runs of 4+ as (128 + n, byte), the rest as literals."""
    out, x = bytearray(), 0
    while x < len(data):
        run = 1
        while x + run < len(data) and run < 127 and data[x + run] == data[x]:
            run += 1
        if run >= 4:
            out += bytes([128 + run, data[x]])
            x += run
            continue
        start = x
        while x < len(data) and x - start < 128:
            ahead = data[x:x + 4]
            if len(ahead) == 4 and len(set(ahead)) == 1:
                break
            x += 1
        out += bytes([x - start]) + data[start:x]
    return bytes(out)


def rle(width, height, px):
    body = bytearray()
    for y in range(height):
        line = px[y * width:(y + 1) * width]
        body += bytes([2, 2, width >> 8, width & 255])
        for c in range(4):
            body += rle_channel(bytes(p[c] for p in line))
    return HEADER + b"-Y %d +X %d\n" % (height, width) + bytes(body)


def old_rle(width, height, px):
    """Radiance's old RLE: a run after its first pixel as (1,1,1,n) markers, low byte first."""
    body = bytearray()
    for y in range(height):
        line = px[y * width:(y + 1) * width]
        x = 0
        while x < width:
            run = 1
            while x + run < width and line[x + run] == line[x]:
                run += 1
            body += line[x]
            repeat = run - 1
            while repeat:
                body += bytes([1, 1, 1, repeat & 255])
                repeat >>= 8
            x += run
    return HEADER + b"-Y %d +X %d\n" % (height, width) + bytes(body)


def seeds():
    rng = random.Random(2014)
    s = {}
    s["flat_4x3.hdr"] = flat(b"-Y 3 +X 4", pixels(12, rng))
    s["flat_9x2.hdr"] = flat(b"-Y 2 +X 9", pixels(18, rng))
    s["flat_rgbe_magic.hdr"] = s["flat_4x3.hdr"].replace(b"#?RADIANCE", b"#?RGBE")
    s["flat_crlf_header.hdr"] = s["flat_4x3.hdr"].replace(b"\n", b"\r\n", 4)
    s["flat_zero_pixels.hdr"] = flat(b"-Y 2 +X 3", [bytes(4)] * 6)
    s["rle_12x4.hdr"] = rle(12, 4, pixels(48, rng, runs=True))
    s["rle_16x2_long_runs.hdr"] = rle(16, 2, [b"\x80\x40\x20\x81"] * 32)
    s["rle_200x1.hdr"] = rle(200, 1, pixels(200, rng, runs=True))
    s["old_rle_10x3.hdr"] = old_rle(10, 3, pixels(30, rng, runs=True))
    s["old_rle_300x1_shift.hdr"] = old_rle(300, 1, [b"\x90\x80\x70\x80"] + [b"\x81\x82\x83\x84"] * 299)
    # the eight orientations of one 3 x 2 image, flat
    px = pixels(6, rng)
    for res in (b"-Y 2 +X 3", b"-Y 2 -X 3", b"+Y 2 +X 3", b"+Y 2 -X 3",
                b"+X 3 -Y 2", b"+X 3 +Y 2", b"-X 3 -Y 2", b"-X 3 +Y 2"):
        s["orient_%s.hdr" % res.decode().replace(" ", "_")] = flat(res, px)
    # vertical crosses: the smallest (faces of 1 texel) and faces of 8, RLE
    s["cross_3x4.hdr"] = flat(b"-Y 4 +X 3", pixels(12, rng))
    face = [bytes([128 + 16 * k, 200, 100, 128]) for k in range(8)]
    s["cross_24x32_rle.hdr"] = rle(24, 32, [face[((x // 8) + 3 * (y // 8)) % 8] for y in range(32) for x in range(24)])
    s["not_cross_6x4.hdr"] = flat(b"-Y 4 +X 6", pixels(24, rng))
    # broken files
    good = s["rle_12x4.hdr"]
    s["bad_truncated_rle.hdr"] = good[:-7]
    s["bad_truncated_flat.hdr"] = s["flat_4x3.hdr"][:-5]
    s["bad_run_past_end.hdr"] = HEADER + b"-Y 1 +X 8\n" + bytes([2, 2, 0, 8, 128 + 40, 7])
    s["bad_literal_past_end.hdr"] = HEADER + b"-Y 1 +X 8\n" + bytes([2, 2, 0, 8, 9]) + bytes(9)
    s["bad_zero_literal.hdr"] = HEADER + b"-Y 1 +X 8\n" + bytes([2, 2, 0, 8, 0, 0])
    s["bad_marker_length.hdr"] = HEADER + b"-Y 1 +X 8\n" + bytes([2, 2, 0, 9]) + bytes(40)
    s["bad_marker_short_line.hdr"] = HEADER + b"-Y 1 +X 4\n" + bytes([2, 2, 0, 4]) + bytes(16)
    s["bad_repeat_first.hdr"] = HEADER + b"-Y 1 +X 4\n" + bytes([1, 1, 1, 3, 9, 9, 9, 130])
    s["bad_repeat_past_end.hdr"] = HEADER + b"-Y 1 +X 4\n" + bytes([9, 9, 9, 130, 1, 1, 1, 4])
    s["bad_repeat_shift.hdr"] = HEADER + b"-Y 1 +X 300\n" + bytes([9, 9, 9, 130, 1, 1, 1, 255, 1, 1, 1, 2])
    s["bad_magic.hdr"] = b"#?RADIANS\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 1\n" + bytes(4)
    s["bad_xyze.hdr"] = good.replace(b"rgbe\n", b"xyze\n")
    s["bad_no_header_end.hdr"] = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n"
    s["bad_resolution.hdr"] = HEADER + b"-Y 2 +Y 3\n" + bytes(24)
    s["bad_resolution_garbage.hdr"] = HEADER + b"-Y two +X 3\n" + bytes(24)
    s["bad_zero_size.hdr"] = HEADER + b"-Y 0 +X 3\n"
    s["bad_huge_size.hdr"] = HEADER + b"-Y 100000 +X 100000\n" + bytes(16)
    s["bad_huge_claim_short_data.hdr"] = HEADER + b"-Y 2000 +X 2000\n" + bytes([2, 2, 7, 208, 130, 5])
    return s


def main(out_dir):
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    for name, data in seeds().items():
        (out / name).write_bytes(data)
    print(f"{len(seeds())} seeds in {out}")


if __name__ == "__main__":
    main(sys.argv[1])
