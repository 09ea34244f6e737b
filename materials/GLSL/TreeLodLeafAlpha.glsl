// Alpha for the alpha test: from the mip level the footprint asks for, but never coarser than
// alphaMaxLod. Coarse mips of a leaf texture lose the leaf's shape, and distant foliage went
// bald (20k-leaf oak at medium distance: FLIP 0.018 against the CPU ray tracer, 0.0019 with the
// clamp at 3); the clamp keeps some prefiltering against sparkle at one sample per pixel.
// Shared by the lit leaves and the leaf shadow caster, so shadows have the same leaf shapes.
float leafAlpha(SAMPLER2D_PARAM(map), vec2 uv, float alphaMaxLod)
{
    vec2 t = uv * vec2(TEX2D_SIZE(map, 0));
    float lod = log2(max(max(length(dFdx(t)), length(dFdy(t))), 1e-6));
    return TEX2D_LOD(map, uv, clamp(lod, 0.0, alphaMaxLod)).a;
}
