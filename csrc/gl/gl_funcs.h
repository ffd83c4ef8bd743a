/* gl_funcs.h - the OpenGL entry points the library uses, fetched through the
 * context backend's get-proc-address. We never link libGL: inside Blender the
 * process-global GL symbols belong to Blender's own context. */
#ifndef VXL_GL_FUNCS_H
#define VXL_GL_FUNCS_H

#define GL_GLEXT_LEGACY 1
#include <GL/glcorearb.h>

#define VXL_GL_FUNC_LIST(X)                                                   \
    X(PFNGLGETSTRINGPROC, GetString)                                          \
    X(PFNGLGETINTEGERVPROC, GetIntegerv)                                      \
    X(PFNGLGETERRORPROC, GetError)                                            \
    X(PFNGLFINISHPROC, Finish)                                                \
    X(PFNGLVIEWPORTPROC, Viewport)                                            \
    X(PFNGLENABLEPROC, Enable)                                                \
    X(PFNGLDISABLEPROC, Disable)                                              \
    X(PFNGLCLEARBUFFERFVPROC, ClearBufferfv)                                  \
    X(PFNGLPIXELSTOREIPROC, PixelStorei)                                      \
    X(PFNGLREADPIXELSPROC, ReadPixels)                                        \
    X(PFNGLGETTEXIMAGEPROC, GetTexImage)                                      \
    X(PFNGLSCISSORPROC, Scissor)                                              \
    X(PFNGLREADBUFFERPROC, ReadBuffer)                                        \
    X(PFNGLDRAWBUFFERSPROC, DrawBuffers)                                      \
    X(PFNGLDRAWARRAYSPROC, DrawArrays)                                        \
    X(PFNGLGENTEXTURESPROC, GenTextures)                                      \
    X(PFNGLDELETETEXTURESPROC, DeleteTextures)                                \
    X(PFNGLBINDTEXTUREPROC, BindTexture)                                      \
    X(PFNGLACTIVETEXTUREPROC, ActiveTexture)                                  \
    X(PFNGLTEXPARAMETERIPROC, TexParameteri)                                  \
    X(PFNGLTEXIMAGE1DPROC, TexImage1D)                                        \
    X(PFNGLTEXIMAGE2DPROC, TexImage2D)                                        \
    X(PFNGLTEXIMAGE3DPROC, TexImage3D)                                        \
    X(PFNGLTEXSUBIMAGE3DPROC, TexSubImage3D)                                  \
    X(PFNGLBINDIMAGETEXTUREPROC, BindImageTexture)                            \
    X(PFNGLGENFRAMEBUFFERSPROC, GenFramebuffers)                              \
    X(PFNGLDELETEFRAMEBUFFERSPROC, DeleteFramebuffers)                        \
    X(PFNGLBINDFRAMEBUFFERPROC, BindFramebuffer)                              \
    X(PFNGLFRAMEBUFFERTEXTURE2DPROC, FramebufferTexture2D)                    \
    X(PFNGLCHECKFRAMEBUFFERSTATUSPROC, CheckFramebufferStatus)                \
    X(PFNGLGENVERTEXARRAYSPROC, GenVertexArrays)                              \
    X(PFNGLDELETEVERTEXARRAYSPROC, DeleteVertexArrays)                        \
    X(PFNGLBINDVERTEXARRAYPROC, BindVertexArray)                              \
    X(PFNGLGENBUFFERSPROC, GenBuffers)                                        \
    X(PFNGLDELETEBUFFERSPROC, DeleteBuffers)                                  \
    X(PFNGLBINDBUFFERPROC, BindBuffer)                                        \
    X(PFNGLBINDBUFFERBASEPROC, BindBufferBase)                                \
    X(PFNGLBUFFERDATAPROC, BufferData)                                        \
    X(PFNGLGETBUFFERSUBDATAPROC, GetBufferSubData)                            \
    X(PFNGLCREATESHADERPROC, CreateShader)                                    \
    X(PFNGLDELETESHADERPROC, DeleteShader)                                    \
    X(PFNGLSHADERSOURCEPROC, ShaderSource)                                    \
    X(PFNGLCOMPILESHADERPROC, CompileShader)                                  \
    X(PFNGLGETSHADERIVPROC, GetShaderiv)                                      \
    X(PFNGLGETSHADERINFOLOGPROC, GetShaderInfoLog)                            \
    X(PFNGLCREATEPROGRAMPROC, CreateProgram)                                  \
    X(PFNGLDELETEPROGRAMPROC, DeleteProgram)                                  \
    X(PFNGLATTACHSHADERPROC, AttachShader)                                    \
    X(PFNGLLINKPROGRAMPROC, LinkProgram)                                      \
    X(PFNGLGETPROGRAMIVPROC, GetProgramiv)                                    \
    X(PFNGLGETPROGRAMINFOLOGPROC, GetProgramInfoLog)                          \
    X(PFNGLUSEPROGRAMPROC, UseProgram)                                        \
    X(PFNGLGETUNIFORMLOCATIONPROC, GetUniformLocation)                        \
    X(PFNGLUNIFORM1IPROC, Uniform1i)                                          \
    X(PFNGLUNIFORM1UIPROC, Uniform1ui)                                        \
    X(PFNGLUNIFORM1FPROC, Uniform1f)                                          \
    X(PFNGLUNIFORM2FPROC, Uniform2f)                                          \
    X(PFNGLUNIFORM3FVPROC, Uniform3fv)                                        \
    X(PFNGLUNIFORM4FVPROC, Uniform4fv)                                        \
    X(PFNGLUNIFORM3IPROC, Uniform3i)                                          \
    X(PFNGLUNIFORMMATRIX3FVPROC, UniformMatrix3fv)                            \
    X(PFNGLUNIFORMMATRIX4FVPROC, UniformMatrix4fv)                            \
    X(PFNGLDISPATCHCOMPUTEPROC, DispatchCompute)                              \
    X(PFNGLMEMORYBARRIERPROC, MemoryBarrier)                                  \
    X(PFNGLCLEARBUFFERSUBDATAPROC, ClearBufferSubData) /* cut/cutaway.c */ \
    /* occluder meshes rasterised into shadow maps (light/shadow_maps.c) */ \
    X(PFNGLDRAWELEMENTSPROC, DrawElements)                                    \
    X(PFNGLVERTEXATTRIBPOINTERPROC, VertexAttribPointer)                      \
    X(PFNGLENABLEVERTEXATTRIBARRAYPROC, EnableVertexAttribArray)              \
    X(PFNGLFRAMEBUFFERTEXTURELAYERPROC, FramebufferTextureLayer)              \
    X(PFNGLDEPTHFUNCPROC, DepthFunc)                                          \
    X(PFNGLDEPTHMASKPROC, DepthMask)                                          \
    X(PFNGLUNIFORM1FVPROC, Uniform1fv)                                        \
    X(PFNGLCOPYIMAGESUBDATAPROC, CopyImageSubData) /* a streamed pool grown keeps its bricks */

typedef struct vxl_gl {
#define VXL_GL_MEMBER(type, name) type name;
    VXL_GL_FUNC_LIST(VXL_GL_MEMBER)
#undef VXL_GL_MEMBER
} vxl_gl;

typedef void (*vxl_gl_proc)(void);
typedef vxl_gl_proc (*vxl_get_proc_fn)(void *user, const char *name);

/* Fills every entry; on failure returns the name of the first missing one. */
const char *vxl_gl_load(vxl_gl *gl, vxl_get_proc_fn get, void *user);

#endif
