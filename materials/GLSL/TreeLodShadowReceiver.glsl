// Vertex side of a shadow receiver (SHADOW_RECEIVER; TreeLodShading.glsl reads the result): the
// point in each of the sun's shadow textures' clip space, up to three (PSSM's splits).
uniform mat4 texViewProj[3]; // param_named_auto texture_viewproj_matrix_array 3

out vec4 vShadowPos0;
out vec4 vShadowPos1;
out vec4 vShadowPos2;

void passShadowPositions(vec4 world)
{
    vShadowPos0 = texViewProj[0] * world;
    vShadowPos1 = texViewProj[1] * world;
    vShadowPos2 = texViewProj[2] * world;
}
