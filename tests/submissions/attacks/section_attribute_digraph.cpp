// EXPECT: refused-source
// Attack: a section name written into the assembly by an attribute, in
// digraphs (<:<: :>:>) and through a macro.
#include "EnvironmentMap.h"

#define PLACE(s) <:<:gnu::__section__(s):>:>
PLACE(".text.hidden") int hidden_table[4] = {1, 2, 3, 4};

Color EnvironmentMap::fetchColor(const Vector3& d) const
{
    (void)d;
    return Color(0, 0, 0);
}

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    (void)u;
    (void)v;
    return Color(addr[0], addr[1], addr[2]);
}
