// EXPECT: refused-source
// Attack: asm goto, spelled with the digraphs <% %> around its body.
#include "EnvironmentMap.h"

Color EnvironmentMap::fetchColor(const Vector3& d) const
<%
    asm goto("" :::: done);
done:
    (void)d;
    return Color(0, 0, 0);
%>

Color EnvironmentMap::readTexture(const float* addr, double u, double v) const
{
    (void)u;
    (void)v;
    return Color(addr[0], addr[1], addr[2]);
}
