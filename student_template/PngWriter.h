// PngWriter.h - write an 8-bit RGB image as a PNG file.
// Provided with the template; you do not need to change it.
#ifndef PNG_WRITER_H
#define PNG_WRITER_H

// rgb: width * height * 3 bytes, top row first. false when the file
// cannot be written.
bool writePng(const char* path, int width, int height, const unsigned char* rgb);

#endif
