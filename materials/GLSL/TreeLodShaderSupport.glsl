// Included by every TreeLod program after its version block (and its #extension lines, which
// must precede any declaration). One source builds as
// GLSL 1.50 (RenderSystem_GL on a GL 3.2 driver), GLSL 3.30 (GL3Plus, or GL on a newer driver),
// GLSL ES 3.00 (GLES2 on an ES 3 context) and HLSL Shader Model 4 (`hlsl` programs, target
// vs_4_0 / ps_4_0, for RenderSystem_Direct3D11); OGRE defines OGRE_GLSL, OGRE_GLSLES or
// OGRE_HLSL (4 under Direct3D 11) with the render system's shading language version, and
// OGRE_VERTEX_SHADER or OGRE_FRAGMENT_SHADER. The version block, verbatim in each program
// (OGRE reads a GLSL program's version from its own text, before includes are resolved; HLSL
// gets no #version line):
//   #if defined(OGRE_GLSLES)
//   #version 300 es
//   #elif OGRE_GLSL >= 330
//   #version 330 core
//   #elif defined(OGRE_GLSL)
//   #version 150
//   #endif
// GLSL 1.20 and ES 1.00 are not targets: the programs fetch texels by integer coordinates and
// pack cell indices in bits (texelFetch, uint, bit operators: GLSL 1.30, ES 3.00, SM4).
// HLSL is compile-checked only (tests/shaders/validate-hlsl.py, glslang's HLSL front end); no
// Direct3D runs it here. Cg (OGRE_CG without OGRE_HLSL) is not a target: it would take the GLSL side.
//
// The sources are GLSL with the differences to HLSL written as the macros below, in the style of
// OGRE's OgreUnifiedShader.h (which TreeLod does not include: its GLSL side declares inputs with
// `attribute`/`varying`, which GLSL 3.30 core and ES 3.00 reject):
// - mul(M, v) for M * v: Ogre hands HLSL its matrices so that mul(M, v) is M * v in GLSL;
//   row3(M, i) is row i of M's upper 3x3; toMat3(M) is mat3(M); mtxFromCols(a, b, c) is mat3(a, b, c);
// - vec3_splat(x) for vec3(x) (an HLSL vector takes one scalar by a cast, not a constructor);
// - depth: NDC z runs from NDC_NEAR (GL -1, Direct3D 0) to 1; WINDOW_DEPTH(z) is the depth buffer's
//   value of NDC z (GL 0.5 z + 0.5, Direct3D z). The shadow casters' colour output keeps
//   0.5 z + 0.5 everywhere: the receivers compute the same from texture_viewproj_matrix;
// - STATIC before global constants (a global HLSL const without static is a uniform);
// - textures: SAMPLER2D(name, unit) / SAMPLERCUBE declare a sampler at texture unit `unit` (HLSL:
//   a Texture2D and a SamplerState in registers t<unit> and s<unit>); TEX2D, TEX2D_LOD, TEX2D_GRAD,
//   TEX2D_FETCH, TEX2D_SIZE, TEXCUBE_LOD read them; SAMPLER2D_PARAM(name) / SAMPLER2D_ARG(name)
//   pass one to a function;
// - the stage interface is main's parameter list: MAIN_PARAMETERS, then IN(type name, SEMANTIC),
//   OUT(...), FLAT_IN(...), FLAT_OUT(...), then MAIN_DECLARATION (fragment programs: also
//   fragColour, and with MAIN_DECLARATION_DEPTH gl_FragDepth). GLSL declares them as globals;
//   HLSL makes them main's parameters, so functions take what they need as arguments. A vertex
//   program's outputs and its fragment programs' inputs are declared in the same order with the
//   same semantics (Direct3D links the stages by their signatures).
#ifdef OGRE_HLSL
#define vec2 float2
#define vec3 float3
#define vec4 float4
#define ivec2 int2
#define ivec3 int3
#define ivec4 int4
#define uvec4 uint4
#define mat3 float3x3
#define mat4 float4x4
#define mix lerp
#define fract frac
#define inversesqrt rsqrt
#define dFdx ddx
#define dFdy ddy
#define lessThan(a, b) ((a) < (b))
#define greaterThan(a, b) ((a) > (b))
#define inverse treeLodInverse
#define vec2_splat(x) ((float2)(x))
#define vec3_splat(x) ((float3)(x))
#define vec4_splat(x) ((float4)(x))
#define ivec2_splat(x) ((int2)(x))
#define ivec3_splat(x) ((int3)(x))
#define row3(m, i) ((m)[i].xyz)
#define toMat3(m) ((float3x3)(m))
#define mtxFromCols(a, b, c) transpose(float3x3(a, b, c))
#define STATIC static
#define NDC_NEAR 0.0
#define WINDOW_DEPTH(z) (z)

#define TREELOD_REGISTER(kind, unit) register(kind##unit)
#define SAMPLER2D(name, unit) Texture2D name : TREELOD_REGISTER(t, unit); SamplerState name##Sampler : TREELOD_REGISTER(s, unit)
#define SAMPLERCUBE(name, unit) TextureCube name : TREELOD_REGISTER(t, unit); SamplerState name##Sampler : TREELOD_REGISTER(s, unit)
#define SAMPLER2D_PARAM(name) Texture2D name, SamplerState name##Sampler
#define SAMPLER2D_ARG(name) name, name##Sampler
#define TEX2D(name, uv) name.Sample(name##Sampler, uv)
#define TEX2D_LOD(name, uv, lod) name.SampleLevel(name##Sampler, uv, lod)
#define TEX2D_GRAD(name, uv, dx, dy) name.SampleGrad(name##Sampler, uv, dx, dy)
#define TEX2D_FETCH(name, at, lod) name.Load(int3(at, lod))
#define TEX2D_SIZE(name, lod) treeLodTextureSize(name, lod)
#define TEXCUBE_LOD(name, dir, lod) name.SampleLevel(name##Sampler, dir, lod)

int2 treeLodTextureSize(Texture2D map, int lod)
{
    uint width, height, levels;
    map.GetDimensions(uint(lod), width, height, levels);
    return int2(int(width), int(height));
}

// GLSL's inverse(mat3): the adjugate over the determinant.
float3x3 treeLodInverse(float3x3 m)
{
    float3 c0 = cross(m[1], m[2]), c1 = cross(m[2], m[0]), c2 = cross(m[0], m[1]);
    return transpose(float3x3(c0, c1, c2)) / dot(m[0], c0);
}

#define MAIN_PARAMETERS void main(
#define IN(decl, semantic) in decl : semantic,
#define OUT(decl, semantic) out decl : semantic,
#define FLAT_IN(decl, semantic) nointerpolation in decl : semantic,
#define FLAT_OUT(decl, semantic) nointerpolation out decl : semantic,
#ifdef OGRE_VERTEX_SHADER
#define MAIN_DECLARATION out float4 gl_Position : SV_Position)
#else
#define MAIN_DECLARATION in float4 gl_FragCoord : SV_Position, out float4 fragColour : SV_Target)
#define MAIN_DECLARATION_DEPTH in float4 gl_FragCoord : SV_Position, out float4 fragColour : SV_Target, out float gl_FragDepth : SV_Depth)
#endif
#else // GLSL, GLSL ES
#ifdef OGRE_GLSLES
// ES has no default float precision in fragment programs and none for these sampler types.
precision highp float;
precision highp int;
precision highp sampler2D;
precision highp samplerCube;
#endif
#define mul(a, b) ((a) * (b))
#define vec2_splat vec2
#define vec3_splat vec3
#define vec4_splat vec4
#define ivec2_splat ivec2
#define ivec3_splat ivec3
#define row3(m, i) vec3((m)[0][i], (m)[1][i], (m)[2][i])
#define toMat3 mat3
#define mtxFromCols mat3
#define STATIC
#define NDC_NEAR (-1.0)
#define WINDOW_DEPTH(z) (0.5 * (z) + 0.5)

#define SAMPLER2D(name, unit) uniform sampler2D name
#define SAMPLERCUBE(name, unit) uniform samplerCube name
#define SAMPLER2D_PARAM(name) sampler2D name
#define SAMPLER2D_ARG(name) name
#define TEX2D(name, uv) texture(name, uv)
#define TEX2D_LOD(name, uv, lod) textureLod(name, uv, lod)
#define TEX2D_GRAD(name, uv, dx, dy) textureGrad(name, uv, dx, dy)
#define TEX2D_FETCH(name, at, lod) texelFetch(name, at, lod)
#define TEX2D_SIZE(name, lod) textureSize(name, lod)
#define TEXCUBE_LOD(name, dir, lod) textureLod(name, dir, lod)

#define MAIN_PARAMETERS
#define IN(decl, semantic) in decl;
#define OUT(decl, semantic) out decl;
#define FLAT_IN(decl, semantic) flat in decl;
#define FLAT_OUT(decl, semantic) flat out decl;
#ifdef OGRE_VERTEX_SHADER
#define MAIN_DECLARATION void main()
#else
#define MAIN_DECLARATION out vec4 fragColour; void main()
#define MAIN_DECLARATION_DEPTH MAIN_DECLARATION
#endif
#endif
