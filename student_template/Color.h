// Color.h - a linear RGB colour of doubles (HDR: values may exceed 1).
// Provided with the template; you do not need to change it.
#ifndef COLOR_H
#define COLOR_H

struct Color
{
    double r, g, b;

    Color() : r(0.0), g(0.0), b(0.0) {}
    Color(double r_, double g_, double b_) : r(r_), g(g_), b(b_) {}

    Color operator+(const Color& o) const { return Color(r + o.r, g + o.g, b + o.b); }
    Color operator-(const Color& o) const { return Color(r - o.r, g - o.g, b - o.b); }
    Color operator*(double s) const { return Color(r * s, g * s, b * s); }
    Color operator/(double s) const { return Color(r / s, g / s, b / s); }
    // Component-wise product (e.g. a filter colour times light).
    Color operator*(const Color& o) const { return Color(r * o.r, g * o.g, b * o.b); }
    Color& operator+=(const Color& o) { r += o.r; g += o.g; b += o.b; return *this; }
    Color& operator*=(double s) { r *= s; g *= s; b *= s; return *this; }
};

inline Color operator*(double s, const Color& c) { return c * s; }

#endif
