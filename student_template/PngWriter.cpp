// PngWriter.cpp - a dependency-free PNG writer.
//
// The pixels are stored, not compressed: the zlib stream inside IDAT uses
// deflate's "stored" blocks (no Huffman coding), which every PNG reader
// accepts. Files are about as large as the raw pixels; simplicity wins here.
// Format: the PNG specification (W3C, 2003), chunks IHDR, IDAT, IEND;
// zlib (RFC 1950) with deflate stored blocks (RFC 1951, section 3.2.4).
#include "PngWriter.h"

#include <cstdint>
#include <cstdio>
#include <vector>

namespace {

std::uint32_t crc32Update(std::uint32_t crc, const unsigned char* data, std::size_t size)
{
    static std::uint32_t table[256];
    static bool tableReady = false;
    if (!tableReady) {
        for (std::uint32_t n = 0; n < 256; ++n) {
            std::uint32_t c = n;
            for (int k = 0; k < 8; ++k)
                c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
            table[n] = c;
        }
        tableReady = true;
    }
    for (std::size_t i = 0; i < size; ++i)
        crc = table[(crc ^ data[i]) & 0xFF] ^ (crc >> 8);
    return crc;
}

std::uint32_t adler32(const std::vector<unsigned char>& data)
{
    std::uint32_t a = 1, b = 0;
    for (unsigned char byte : data) {
        a = (a + byte) % 65521;
        b = (b + a) % 65521;
    }
    return (b << 16) | a;
}

void putBigEndian32(std::vector<unsigned char>& out, std::uint32_t value)
{
    out.push_back(static_cast<unsigned char>(value >> 24));
    out.push_back(static_cast<unsigned char>(value >> 16));
    out.push_back(static_cast<unsigned char>(value >> 8));
    out.push_back(static_cast<unsigned char>(value));
}

// A chunk: length, type, data, CRC of type and data.
void putChunk(std::vector<unsigned char>& out, const char type[4], const std::vector<unsigned char>& data)
{
    putBigEndian32(out, static_cast<std::uint32_t>(data.size()));
    const std::size_t typeStart = out.size();
    out.insert(out.end(), type, type + 4);
    out.insert(out.end(), data.begin(), data.end());
    const std::uint32_t crc = crc32Update(0xFFFFFFFFu, out.data() + typeStart, 4 + data.size());
    putBigEndian32(out, crc ^ 0xFFFFFFFFu);
}

// zlib stream of `raw` in stored deflate blocks of at most 65535 bytes.
std::vector<unsigned char> zlibStored(const std::vector<unsigned char>& raw)
{
    std::vector<unsigned char> out = {0x78, 0x01};   // deflate, 32 KiB window, no dictionary
    std::size_t offset = 0;
    do {
        const std::size_t size = raw.size() - offset < 65535 ? raw.size() - offset : 65535;
        const bool last = offset + size == raw.size();
        out.push_back(last ? 1 : 0);                  // BFINAL, BTYPE = 00 (stored)
        out.push_back(static_cast<unsigned char>(size & 0xFF));
        out.push_back(static_cast<unsigned char>(size >> 8));
        out.push_back(static_cast<unsigned char>(~size & 0xFF));
        out.push_back(static_cast<unsigned char>((~size >> 8) & 0xFF));
        out.insert(out.end(), raw.begin() + offset, raw.begin() + offset + size);
        offset += size;
    } while (offset < raw.size());
    putBigEndian32(out, adler32(raw));
    return out;
}

} // namespace

bool writePng(const char* path, int width, int height, const unsigned char* rgb)
{
    if (width <= 0 || height <= 0)
        return false;
    const std::size_t rowBytes = static_cast<std::size_t>(width) * 3;

    // Each scanline is filter type 0 (none) followed by its pixels.
    std::vector<unsigned char> raw;
    raw.reserve((rowBytes + 1) * height);
    for (int y = 0; y < height; ++y) {
        raw.push_back(0);
        raw.insert(raw.end(), rgb + y * rowBytes, rgb + (y + 1) * rowBytes);
    }

    std::vector<unsigned char> header;
    putBigEndian32(header, static_cast<std::uint32_t>(width));
    putBigEndian32(header, static_cast<std::uint32_t>(height));
    header.insert(header.end(), {8, 2, 0, 0, 0});     // 8 bits, RGB, deflate, filter 0, no interlace

    std::vector<unsigned char> file = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
    putChunk(file, "IHDR", header);
    putChunk(file, "IDAT", zlibStored(raw));
    putChunk(file, "IEND", {});

    std::FILE* out = std::fopen(path, "wb");
    if (!out)
        return false;
    const bool written = std::fwrite(file.data(), 1, file.size(), out) == file.size();
    return std::fclose(out) == 0 && written;
}
