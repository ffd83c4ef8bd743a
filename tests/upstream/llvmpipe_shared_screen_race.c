/* llvmpipe_shared_screen_race.c - Mesa's llvmpipe (22.3.6, Debian 12) reads
 * freed memory when two contexts of one screen run GL at the same time.
 *
 * No Voxlight code: two OSMesa contexts (OSMesa gives every context of a
 * process the same llvmpipe screen), one thread each. Each thread draws one
 * scene that outgrows its first 64 KiB data block (a new state and a newly
 * written SSBO per draw), flushes it, then maps a buffer (glBufferData on a
 * buffer of the same size). The map calls llvmpipe_flush_resource, which
 * walks the queued scenes of EVERY context on the screen
 * (lp_setup_is_resource_referenced -> lp_scene_is_resource_referenced) while
 * the other context's thread frees and refills its own scenes' resource
 * lists (lp_scene_end_rasterization, lp_scene_add_resource_reference). The
 * reader follows a freed block: SEGV at libOSMesa.so.8+0x68fa61 / +0x68fa40
 * / +0x68f9fc with frames +0x692b28 and +0x68081d, the stack of the CI crash
 * (../../../shared/reference/ci-failures/test_stress_asan_segv.txt).
 *
 * Build and run (libosmesa6; ASan fills freed memory so the stale read
 * crashes at once instead of 1 run in 4):
 *   gcc -O1 -g -fsanitize=address tests/upstream/llvmpipe_shared_screen_race.c \
 *       -o /tmp/race -l:libOSMesa.so.8 -lpthread
 *   ASAN_OPTIONS=detect_leaks=0:max_free_fill_size=1048576:free_fill_byte=190 /tmp/race 500 0   # crashes
 *   ASAN_OPTIONS=detect_leaks=0:max_free_fill_size=1048576:free_fill_byte=190 /tmp/race 500 1   # "clean"
 * The second argument 1 makes the two threads take turns under one mutex,
 * which is Voxlight's workaround (csrc/gl/context.h, vxl_context_screen_lock).
 * Measured here: unlocked 3 of 3 runs crashed; locked 3 of 3 clean (25 s each). */
#define GL_GLEXT_PROTOTYPES
#include <GL/gl.h>
#include <GL/glext.h>
/* osmesa.h is not installed with libosmesa6: its stable ABI, as csrc/gl/backend_osmesa.c */
typedef struct osmesa_context *OSMesaContext;
#define OSMESA_RGBA GL_RGBA
#define OSMESA_FORMAT 0x22
#define OSMESA_PROFILE 0x33
#define OSMESA_CORE_PROFILE 0x34
#define OSMESA_CONTEXT_MAJOR_VERSION 0x36
#define OSMESA_CONTEXT_MINOR_VERSION 0x37
OSMesaContext OSMesaCreateContextAttribs(const int*,OSMesaContext);GLboolean OSMesaMakeCurrent(OSMesaContext,void*,GLenum,GLsizei,GLsizei);void OSMesaDestroyContext(OSMesaContext);
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
static int ITER = 2000, LOCKED = 0;
static pthread_mutex_t screen_lock = PTHREAD_MUTEX_INITIALIZER;
static const char *vs = "#version 450\nvoid main(){vec2 p=vec2((gl_VertexID<<1)&2,gl_VertexID&2);gl_Position=vec4(p*2.0-1.0,0,1);}";
static const char *fs = "#version 450\nlayout(std430,binding=0) buffer S{uint n[];};\n"
 "uniform float u;uniform sampler3D t[16];out vec4 o;void main(){vec4 a=vec4(0);for(int i=0;i<16;i++)a+=texture(t[i],vec3(gl_FragCoord.xy/64.0,0.5));atomicAdd(n[0],1u);o=a+u;}";
static GLuint sh(GLenum k,const char*s){GLuint h=glCreateShader(k);glShaderSource(h,1,&s,NULL);glCompileShader(h);GLint ok;glGetShaderiv(h,GL_COMPILE_STATUS,&ok);if(!ok){char b[2000];glGetShaderInfoLog(h,2000,NULL,b);fprintf(stderr,"%s\n",b);exit(2);}return h;}
static void *run(void *arg){
  (void)arg;
  const int at[]={OSMESA_FORMAT,OSMESA_RGBA,OSMESA_PROFILE,OSMESA_CORE_PROFILE,OSMESA_CONTEXT_MAJOR_VERSION,4,OSMESA_CONTEXT_MINOR_VERSION,5,0};
  OSMesaContext c=OSMesaCreateContextAttribs(at,NULL); static __thread unsigned char buf[64*64*4];
  if(!c||!OSMesaMakeCurrent(c,buf,GL_UNSIGNED_BYTE,64,64)){fprintf(stderr,"ctx\n");exit(2);}
  GLuint p=glCreateProgram();glAttachShader(p,sh(GL_VERTEX_SHADER,vs));glAttachShader(p,sh(GL_FRAGMENT_SHADER,fs));glLinkProgram(p);glUseProgram(p);
  GLuint tex[16];glGenTextures(16,tex);float *vox=calloc(16*16*16,4);
  for(int i=0;i<16;i++){glActiveTexture(GL_TEXTURE0+i);glBindTexture(GL_TEXTURE_3D,tex[i]);glTexImage3D(GL_TEXTURE_3D,0,GL_R32F,16,16,16,0,GL_RED,GL_FLOAT,vox);
    glTexParameteri(GL_TEXTURE_3D,GL_TEXTURE_MIN_FILTER,GL_LINEAR);char n[16];snprintf(n,16,"t[%d]",i);glUniform1i(glGetUniformLocation(p,n),i);}
  GLuint vao;glGenVertexArrays(1,&vao);glBindVertexArray(vao);
  GLuint fbo,rb;glGenFramebuffers(1,&fbo);glGenRenderbuffers(1,&rb);glBindRenderbuffer(GL_RENDERBUFFER,rb);glRenderbufferStorage(GL_RENDERBUFFER,GL_RGBA32F,64,64);
  glBindFramebuffer(GL_FRAMEBUFFER,fbo);glFramebufferRenderbuffer(GL_FRAMEBUFFER,GL_COLOR_ATTACHMENT0,GL_RENDERBUFFER,rb);
  GLuint ssbo[64];glGenBuffers(64,ssbo);const GLuint z[4]={0};
  for(int i=0;i<64;i++){glBindBuffer(GL_SHADER_STORAGE_BUFFER,ssbo[i]);glBufferData(GL_SHADER_STORAGE_BUFFER,16,z,GL_DYNAMIC_READ);}
  float px[64*64*4];
  for(int it=0;it<ITER;it++){
    if(LOCKED)pthread_mutex_lock(&screen_lock);
    for(int d=0;d<64;d++){ /* one scene that outgrows its first data block: a new state and a new written SSBO per draw */
      glUniform1f(glGetUniformLocation(p,"u"),(float)d);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER,0,ssbo[d]);glViewport(0,0,64,64);glDrawArrays(GL_TRIANGLES,0,3);}
    glFlush();
    glBindBuffer(GL_SHADER_STORAGE_BUFFER,ssbo[it%64]);glBufferData(GL_SHADER_STORAGE_BUFFER,16,z,GL_DYNAMIC_READ);
    glReadPixels(0,0,64,64,GL_RGBA,GL_FLOAT,px);
    if(LOCKED)pthread_mutex_unlock(&screen_lock);
  }
  OSMesaDestroyContext(c);return NULL;}
int main(int argc,char**argv){ if(argc>1)ITER=atoi(argv[1]); if(argc>2)LOCKED=atoi(argv[2]);
  pthread_t a,b;pthread_create(&a,NULL,run,NULL);pthread_create(&b,NULL,run,NULL);pthread_join(a,NULL);pthread_join(b,NULL);puts("clean");return 0;}
