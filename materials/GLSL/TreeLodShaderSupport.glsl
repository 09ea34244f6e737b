// Included by every TreeLod program after its version block (and its #extension lines, which
// must precede any declaration). One source builds as
// GLSL 1.50 (RenderSystem_GL on a GL 3.2 driver), GLSL 3.30 (GL3Plus, or GL on a newer driver)
// and GLSL ES 3.00 (GLES2 on an ES 3 context); OGRE defines OGRE_GLSL or OGRE_GLSLES with the
// render system's shading language version. The version block, verbatim in each program
// (OGRE reads a program's version from its own text, before includes are resolved):
//   #if defined(OGRE_GLSLES)
//   #version 300 es
//   #elif OGRE_GLSL >= 330
//   #version 330 core
//   #else
//   #version 150
//   #endif
// GLSL 1.20 and ES 1.00 are not targets: the programs fetch texels by integer coordinates and
// pack cell indices in bits (texelFetch, uint, bit operators: GLSL 1.30, ES 3.00).
#ifdef OGRE_GLSLES
// ES has no default float precision in fragment programs and none for these sampler types.
precision highp float;
precision highp int;
precision highp sampler2D;
precision highp samplerCube;
#endif
