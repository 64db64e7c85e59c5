"""The reference RGBE (.hdr) reader and writer (reference/src/rgbe.c).

Expected pixels come from an independent decoder written here (numpy:
m * 2^(e-136), 0 when e == 0) over files whose bytes are assembled here, and
from OpenImageIO for real files and for everything our writer produces.
"""
from __future__ import annotations


import numpy as np
import OpenImageIO as oiio
import pytest

from grader import PROJECT_ROOT
from grader.envmap.library import EnvmapError, read_hdr, read_hdr_bytes, write_hdr

from grader import PROBES
REAL_HDR_FILES = sorted(PROBES.glob("*.hdr")) + sorted((PROJECT_ROOT / "Cubemap").glob("*.hdr"))

# em_status values from envmap.h
EM_ERR_IO, EM_ERR_FORMAT, EM_ERR_CORRUPT, EM_ERR_TOO_LARGE = -1, -2, -3, -4

HEADER = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n"


# ---- an independent model of the format ------------------------------------

def decode(rgbe: np.ndarray) -> np.ndarray:
    """RGBE bytes (..., 4) -> float32 (..., 3), as Ward/stb/OpenImageIO define it."""
    m = rgbe[..., :3].astype(np.float64)
    e = rgbe[..., 3:].astype(np.int64)
    return np.where(e == 0, 0.0, np.ldexp(m, e - 136)).astype(np.float32)


def random_rgbe(rng, height, width, runs=False) -> np.ndarray:
    """(H, W, 4) uint8 pixels whose first bytes never look like RLE markers (>= 3);
    with runs, rows repeat pixels so RLE has something to compress."""
    px = np.empty((height, width, 4), np.uint8)
    px[..., 0] = rng.integers(128, 256, (height, width))
    px[..., 1:3] = rng.integers(3, 256, (height, width, 2))
    px[..., 3] = rng.integers(100, 160, (height, width))
    if runs:
        keep = rng.random((height, width)) < 0.3
        keep[:, 0] = True
        index = np.maximum.accumulate(np.where(keep, np.arange(width), 0), axis=1)
        px = np.take_along_axis(px, index[..., None], axis=1)
    return px


def hdr_file(resolution: str, body: bytes, header: bytes = HEADER) -> bytes:
    return header + resolution.encode() + b"\n" + body


def rle_channel(data: bytes) -> bytes:
    """New-style RLE of one channel: greedy runs of 3+ (max 127), literals (max 128)."""
    out, x = bytearray(), 0
    while x < len(data):
        run = 1
        while x + run < len(data) and run < 127 and data[x + run] == data[x]:
            run += 1
        if run >= 3:
            out += bytes([128 + run, data[x]])
            x += run
        else:
            n = min(run, 128)
            out += bytes([n]) + data[x:x + n]
            x += n
    return bytes(out)


def new_rle_body(px: np.ndarray) -> bytes:
    h, w, _ = px.shape
    out = bytearray()
    for row in px:
        out += bytes([2, 2, w >> 8, w & 255])
        for c in range(4):
            out += rle_channel(row[:, c].tobytes())
    return bytes(out)


def old_rle_body(px: np.ndarray) -> bytes:
    """Radiance's old-style RLE: a pixel, then (1, 1, 1, n) markers repeating it,
    consecutive markers worth n, n << 8, n << 16 (low byte first)."""
    out = bytearray()
    for row in px:
        x = 0
        while x < len(row):
            run = 1
            while x + run < len(row) and np.array_equal(row[x + run], row[x]):
                run += 1
            out += row[x].tobytes()
            repeat = run - 1
            while repeat:
                out += bytes([1, 1, 1, repeat & 255])
                repeat >>= 8
            x += run
    return bytes(out)


def oiio_read(path) -> np.ndarray:
    inp = oiio.ImageInput.open(str(path))
    assert inp is not None, oiio.geterror()
    try:
        return inp.read_image(0, 0, 0, 3, "float")
    finally:
        inp.close()


def assert_bits_equal(actual: np.ndarray, expected: np.ndarray) -> None:
    assert actual.shape == expected.shape
    differ = actual.view(np.uint32) != expected.view(np.uint32)
    if differ.any():
        where = tuple(np.argwhere(differ)[0])
        pytest.fail(f"{differ.sum()} values differ; first at {where}: "
                    f"{actual[where]!r} != {expected[where]!r}")


# ---- real files ---------------------------------------------------------------

@pytest.mark.parametrize("path", REAL_HDR_FILES, ids=lambda p: p.name)
def test_real_file_is_bit_identical_to_openimageio(path):
    assert_bits_equal(read_hdr(path), oiio_read(path))


# ---- orientations -------------------------------------------------------------

# The file's scanlines (row s = scanline s) for each resolution line, from
# the standard image (top row first): the first axis advances per scanline,
# the second along it; +X runs left to right, -Y top to bottom.
ORIENTATIONS = {
    "-Y {h} +X {w}": lambda img: img,
    "-Y {h} -X {w}": lambda img: img[:, ::-1],
    "+Y {h} +X {w}": lambda img: img[::-1],
    "+Y {h} -X {w}": lambda img: img[::-1, ::-1],
    "+X {w} -Y {h}": lambda img: img.transpose(1, 0, 2),
    "+X {w} +Y {h}": lambda img: img[::-1].transpose(1, 0, 2),
    "-X {w} -Y {h}": lambda img: img[:, ::-1].transpose(1, 0, 2),
    "-X {w} +Y {h}": lambda img: img[::-1, ::-1].transpose(1, 0, 2),
}


@pytest.mark.parametrize("resolution", ORIENTATIONS)
def test_every_orientation_is_turned_into_top_row_first(resolution, tmp_path):
    rng = np.random.default_rng(8)
    image = random_rgbe(rng, 5, 7)  # H != W, so a transpose cannot pass by accident
    scanlines = np.ascontiguousarray(ORIENTATIONS[resolution](image))
    data = hdr_file(resolution.format(h=5, w=7), scanlines.tobytes())
    assert_bits_equal(read_hdr_bytes(data, "oriented.hdr"), decode(image))
    # OpenImageIO keeps file order and records an EXIF Orientation; for the
    # flips, reorienting agrees. (For the transposed ones its hdr reader gives
    # "+X +Y" EXIF 6 and "-X -Y" EXIF 8, the other way round from Radiance's
    # definition, so only the model above judges those.)
    if resolution.startswith(("+X", "-X")):
        return
    path = tmp_path / "oriented.hdr"
    path.write_bytes(data)
    upright = oiio.ImageBufAlgo.reorient(oiio.ImageBuf(str(path)))
    assert_bits_equal(read_hdr(path), upright.get_pixels(oiio.FLOAT))


# ---- scanline encodings ---------------------------------------------------------

def test_flat_new_rle_and_old_rle_decode_to_the_same_pixels():
    rng = np.random.default_rng(1)
    image = random_rgbe(rng, 6, 300, runs=True)
    image[2, 10:290] = image[2, 9]      # a 281-pixel run: old-RLE needs a shifted second marker
    image[3, 0:300] = image[3, 0]       # a whole line: new-RLE runs longer than 127
    expected = decode(image)
    resolution = "-Y 6 +X 300"
    bodies = {"flat": image.tobytes(), "new": new_rle_body(image), "old": old_rle_body(image)}
    assert len(bodies["new"]) < len(bodies["flat"]) and len(bodies["old"]) < len(bodies["flat"])
    assert bytes([1, 1, 1, 24, 1, 1, 1, 1]) in bodies["old"]  # 24 + (1 << 8) = 280 repeats
    for kind, body in bodies.items():
        assert_bits_equal(read_hdr_bytes(hdr_file(resolution, body), f"{kind}.hdr"), expected)


def test_old_rle_markers_count_256_times_more_when_consecutive():
    pixel, other = bytes([200, 100, 50, 130]), bytes([150, 150, 150, 129])
    body = pixel + bytes([1, 1, 1, 2]) + bytes([1, 1, 1, 1]) + other  # 1 + 2 + 256 + 1 pixels
    got = read_hdr_bytes(hdr_file("-Y 1 +X 260", body), "old.hdr")
    expected = np.array([decode(np.frombuffer(pixel, np.uint8))] * 259
                        + [decode(np.frombuffer(other, np.uint8))])
    assert_bits_equal(got[0], expected)


@pytest.mark.parametrize("width", [8, 127, 128, 129, 1000, 32767])
def test_new_rle_widths_at_the_edges(width):
    image = random_rgbe(np.random.default_rng(width), 2, width, runs=True)
    got = read_hdr_bytes(hdr_file(f"-Y 2 +X {width}", new_rle_body(image)), "rle.hdr")
    assert_bits_equal(got, decode(image))


def test_exponent_zero_is_black_and_extremes_decode_exactly():
    px = np.array([[[255, 255, 255, 0], [255, 0, 128, 1], [255, 255, 255, 255], [128, 3, 3, 136]]], np.uint8)
    got = read_hdr_bytes(hdr_file("-Y 1 +X 4", px.tobytes()), "extremes.hdr")
    assert_bits_equal(got, decode(px))
    assert got[0, 0].tolist() == [0, 0, 0] and got[0, 3, 0] == 128.0
    assert got[0, 2, 0] == np.float32(255 * 2.0 ** 119)


def test_header_variants_are_accepted():
    body = random_rgbe(np.random.default_rng(2), 2, 3)
    expected = decode(body)
    headers = [
        b"#?RGBE\nFORMAT=32-bit_rle_rgbe\n\n",
        b"#?RADIANCE\n# a comment\nEXPOSURE=  2.5\nGAMMA=1\nPRIMARIES=0 0 0 0 0 0 0 0\n"
        b"FORMAT=32-bit_rle_rgbe\nSOFTWARE=test\n\n",
        b"#?RADIANCE\r\nFORMAT=32-bit_rle_rgbe\r\n\r\n",
        b"#?RADIANCE\n\n",  # FORMAT is optional: Radiance assumes RGBE
    ]
    for header in headers:
        data = hdr_file("-Y 2 +X 3", body.tobytes(), header=header)
        assert_bits_equal(read_hdr_bytes(data, "header.hdr"), expected)


# ---- bad files --------------------------------------------------------------------

def _rle_line(width: int, channel_bytes: bytes) -> bytes:
    return bytes([2, 2, width >> 8, width & 255]) + channel_bytes


GOOD_RLE = hdr_file("-Y 4 +X 12", new_rle_body(random_rgbe(np.random.default_rng(3), 4, 12, runs=True)))
GOOD_FLAT = hdr_file("-Y 3 +X 4", random_rgbe(np.random.default_rng(4), 3, 4).tobytes())

# name: (file bytes, expected em_status, words the message must contain)
BAD_FILES = {
    "empty": (b"", EM_ERR_FORMAT, "not a Radiance file"),
    "wrong magic": (b"#?RADIANS\n\n-Y 1 +X 1\n" + bytes(4), EM_ERR_FORMAT, "not a Radiance file"),
    "png": (b"\x89PNG\r\n\x1a\n" + bytes(40), EM_ERR_FORMAT, "not a Radiance file"),
    "xyze": (GOOD_RLE.replace(b"rgbe\n", b"xyze\n"), EM_ERR_FORMAT, "32-bit_rle_xyze"),
    "no header end": (b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n", EM_ERR_FORMAT, "ends before the blank line"),
    "no resolution line": (HEADER, EM_ERR_FORMAT, "ends before the resolution line"),
    "header too long": (b"#?RADIANCE\n" + b"# padding padding padding\n" * 4000 + b"\n-Y 1 +X 1\n" + bytes(4),
                        EM_ERR_FORMAT, "longer than"),
    "garbage resolution": (hdr_file("-Y two +X 3", bytes(24)), EM_ERR_FORMAT, "resolution line"),
    "same axis twice": (hdr_file("-Y 2 +Y 3", bytes(24)), EM_ERR_FORMAT, "resolution line"),
    "negative size": (hdr_file("-Y -2 +X 3", bytes(24)), EM_ERR_FORMAT, "resolution line"),
    "trailing junk on resolution": (hdr_file("-Y 2 +X 3 x", bytes(24)), EM_ERR_FORMAT, "resolution line"),
    "zero height": (hdr_file("-Y 0 +X 3", b""), EM_ERR_FORMAT, "zero size"),
    "zero width": (hdr_file("-Y 3 +X 0", b""), EM_ERR_FORMAT, "zero size"),
    "absurd size": (hdr_file("-Y 100000 +X 100000", bytes(16)), EM_ERR_TOO_LARGE, "larger than the limit"),
    "absurd digits": (hdr_file("-Y 99999999999999999999 +X 1", bytes(16)), EM_ERR_TOO_LARGE, "larger than the limit"),
    "truncated flat": (GOOD_FLAT[:-5], EM_ERR_CORRUPT, "scanline 2: data ends"),
    "truncated rle": (GOOD_RLE[:-3], EM_ERR_CORRUPT, "scanline 3"),
    "no pixels at all": (hdr_file("-Y 2 +X 3", b""), EM_ERR_CORRUPT, "scanline 0: data ends"),
    "huge claim, little data": (hdr_file("-Y 16000 +X 16000", _rle_line(16000, bytes([130, 5]))),
                                EM_ERR_CORRUPT, "data ends"),
    "run past the line": (hdr_file("-Y 1 +X 32", _rle_line(32, bytes([128 + 40, 7]))),
                          EM_ERR_CORRUPT, "run of 40 bytes passes the end of the 32-pixel line"),
    "literal past the line": (hdr_file("-Y 1 +X 8", _rle_line(8, bytes([9]) + bytes(9))),
                              EM_ERR_CORRUPT, "literal of 9 bytes passes the end of the 8-pixel line"),
    "run past the line in the last channel": (
        hdr_file("-Y 1 +X 8", _rle_line(8, bytes([136, 1, 136, 2, 136, 3, 132, 4, 133, 5]))),
        EM_ERR_CORRUPT, "channel 3: run of 5 bytes"),
    "zero-length literal": (hdr_file("-Y 1 +X 8", _rle_line(8, bytes([0, 0]))), EM_ERR_CORRUPT, "literal of 0"),
    "rle marker with the wrong length": (hdr_file("-Y 1 +X 8", _rle_line(9, bytes(40))),
                                         EM_ERR_CORRUPT, "marker gives 9 pixels"),
    "rle in a line too short for rle": (hdr_file("-Y 1 +X 4", _rle_line(4, bytes([4, 1, 2, 3, 4]) * 4)),
                                        EM_ERR_CORRUPT, "cannot encode a 4-pixel line"),
    "old-rle repeat before any pixel": (hdr_file("-Y 1 +X 4", bytes([1, 1, 1, 3, 9, 9, 9, 130])),
                                        EM_ERR_CORRUPT, "no pixel before it"),
    "old-rle repeat past the line": (hdr_file("-Y 1 +X 4", bytes([9, 9, 9, 130, 1, 1, 1, 4])),
                                     EM_ERR_CORRUPT, "repeat of 4 pixels passes the end of the 4-pixel line"),
    "old-rle shifted repeat past the line": (
        hdr_file("-Y 1 +X 300", bytes([9, 9, 9, 130, 1, 1, 1, 255, 1, 1, 1, 2])),
        EM_ERR_CORRUPT, "repeat of 512 pixels"),
}


@pytest.mark.parametrize("case", BAD_FILES)
def test_bad_file_is_an_error_naming_the_file(case):
    data, code, words = BAD_FILES[case]
    with pytest.raises(EnvmapError) as caught:
        read_hdr_bytes(data, "broken.hdr")
    assert caught.value.code == code, str(caught.value)
    assert str(caught.value).startswith("broken.hdr: ")
    assert words in str(caught.value)


def test_bad_file_on_disk_names_its_path(tmp_path):
    path = tmp_path / "cut.hdr"
    path.write_bytes(GOOD_RLE[:-3])
    with pytest.raises(EnvmapError) as caught:
        read_hdr(path)
    assert caught.value.code == EM_ERR_CORRUPT and str(caught.value).startswith(f"{path}: ")


def test_missing_file_is_an_io_error(tmp_path):
    with pytest.raises(EnvmapError) as caught:
        read_hdr(tmp_path / "nothing.hdr")
    assert caught.value.code == EM_ERR_IO and "nothing.hdr" in str(caught.value)


def test_every_prefix_of_a_good_file_is_an_error():
    """Cutting a file anywhere gives an error, never a crash or a short image."""
    for data in (GOOD_RLE, GOOD_FLAT, hdr_file("-Y 2 +X 9", old_rle_body(random_rgbe(
            np.random.default_rng(5), 2, 9, runs=True)))):
        for cut in range(len(data)):
            with pytest.raises(EnvmapError):
                read_hdr_bytes(data[:cut], "prefix.hdr")


# ---- writing ------------------------------------------------------------------------

def ward_float_to_rgbe(rgb: np.ndarray) -> np.ndarray:
    """Ward's conversion, written independently: the largest channel's frexp
    exponent is shared and mantissas are truncated (float32 throughout)."""
    rgb = rgb.astype(np.float32)
    largest = rgb.max(axis=-1)
    mant, exp = np.frexp(largest)
    with np.errstate(divide="ignore", invalid="ignore"):
        scale = (mant.astype(np.float32) * np.float32(256)) / largest
        m = np.floor(rgb * scale[..., None])
    out = np.zeros(rgb.shape[:-1] + (4,), np.uint8)
    keep = largest >= np.float32(1e-32)
    out[keep, :3] = m[keep]
    out[keep, 3] = exp[keep] + 128
    return out


def hdr_test_image(rng, height, width) -> np.ndarray:
    """Floats over RGBE's range: log-uniform magnitudes, zeros, tiny values, flat runs."""
    img = np.exp(rng.uniform(-20, 20, (height, width, 3))).astype(np.float32)
    specials = np.array([[0, 0, 0], [1e-33, 0, 0], [1e38, 1.0, 0.0], [0, 2e-32, 5.0]], np.float32)
    n = min(width, len(specials))
    img[0, :n] = specials[:n]
    img[1, 1:] = img[1, 0]          # a long run for the RLE
    return img


@pytest.mark.parametrize("width", [1, 7, 8, 33, 300, 32767, 32768])
def test_writer_round_trips_through_openimageio(width, tmp_path):
    height = 3 if width < 10000 else 2
    image = hdr_test_image(np.random.default_rng(width), height, width)
    path = tmp_path / "written.hdr"
    write_hdr(path, image)
    ours = read_hdr(path)
    assert_bits_equal(ours, oiio_read(path))
    # within RGBE precision: truncation loses less than 1/128 of the largest
    # channel; pixels whose largest channel is below 1e-32 are written black
    largest = image.max(axis=-1, keepdims=True)
    black = (largest < 1e-32)[..., 0]
    assert np.all(ours[black] == 0)
    assert np.all(ours <= image)
    assert np.all((image - ours)[~black] <= (largest / 128)[~black])
    # and exactly what Ward's conversion gives
    assert_bits_equal(ours, decode(ward_float_to_rgbe(image)))


@pytest.mark.parametrize("width,rle", [(7, False), (8, True), (32767, True), (32768, False)])
def test_writer_uses_rle_exactly_where_the_width_allows(width, rle, tmp_path):
    path = tmp_path / "w.hdr"
    write_hdr(path, np.full((2, width, 3), 0.5, np.float32))
    data = path.read_bytes()
    body = data[data.index(f"-Y 2 +X {width}\n".encode()) + len(f"-Y 2 +X {width}\n"):]
    assert (body[:4] == bytes([2, 2, width >> 8, width & 255])) == rle
    if rle:
        assert len(body) < 2 * width * 4
    else:
        assert len(body) == 2 * width * 4


def test_writer_is_bit_exact_for_representable_values(tmp_path):
    px = random_rgbe(np.random.default_rng(6), 9, 40, runs=True)
    px[0, 0] = [0, 0, 0, 0]
    image = decode(px)
    path = tmp_path / "exact.hdr"
    write_hdr(path, image)
    assert_bits_equal(read_hdr(path), image)


def test_writer_makes_unrepresentable_values_safe(tmp_path):
    image = np.array([[[np.nan, -1.0, 2.0], [np.inf, 0.0, 1.0], [-np.inf, -0.0, 3e38]]], np.float32)
    path = tmp_path / "odd.hdr"
    write_hdr(path, image)
    back = read_hdr(path)
    biggest = np.float32(255 * 2.0 ** 119)
    assert back[0, 0].tolist() == [0.0, 0.0, 2.0]
    assert back[0, 1, 0] == biggest and back[0, 1, 1] == 0.0
    assert back[0, 2].tolist() == [0.0, 0.0, biggest]
    assert_bits_equal(back, oiio_read(path))


def test_writer_reports_an_unwritable_path(tmp_path):
    with pytest.raises(EnvmapError) as caught:
        write_hdr(tmp_path / "missing" / "dir" / "x.hdr", np.zeros((1, 1, 3), np.float32))
    assert caught.value.code == EM_ERR_IO and "x.hdr" in str(caught.value)
