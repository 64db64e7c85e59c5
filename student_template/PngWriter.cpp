// PngWriter.cpp - write an 8-bit RGB PNG with stb_image_write (public
// domain, third_party/stb_image_write.h, from Debian's libstb-dev): deflate
// compression, so out.png is a few tens of KB instead of the raw pixels.
#include "PngWriter.h"

#if defined(_MSC_VER) && !defined(_CRT_SECURE_NO_WARNINGS)
#define _CRT_SECURE_NO_WARNINGS   // stb uses fopen; MSVC would warn
#endif
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STB_IMAGE_WRITE_STATIC
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wsign-compare"
#endif
#include "stb_image_write.h"
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

bool writePng(const char* path, int width, int height, const unsigned char* rgb)
{
    if (width <= 0 || height <= 0 || !rgb)
        return false;
    stbi_write_png_compression_level = 9;
    return stbi_write_png(path, width, height, 3, rgb, width * 3) != 0;
}
