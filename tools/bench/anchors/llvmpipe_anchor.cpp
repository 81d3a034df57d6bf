// llvmpipe raster anchor (see llvmpipe_anchor.h): the Scene's triangles are uploaded once as
// one interleaved vertex buffer and one index buffer, then each timed frame is glClear, one
// draw of the culled single-sided triangles, one of the double-sided ones, and glFinish (which
// waits for llvmpipe's tile threads, so the wall time is the whole frame).
#include "tools/bench/anchors/llvmpipe_anchor.h"

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <ctime>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <vector>

#include <GLES3/gl3.h>
#include <glm/glm.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "tools/bench/anchors/egl_context.h"

namespace pr::bench {
namespace {

// What the fragment shader needs per vertex. The material's factors are baked into the vertex
// (a vertex shared by triangles of different materials is duplicated), so one draw covers
// every material without a material table lookup.
struct Vertex {
  glm::vec3 position;
  glm::vec3 normal;
  glm::vec3 base;      // linear base colour factor * COLOR_0
  glm::vec3 emission;  // emissiveFactor * emissiveStrength
};

struct Mesh {
  std::vector<Vertex> vertices;
  std::vector<uint32_t> indices;  // single-sided triangles first, then double-sided
  size_t singleSidedIndexCount = 0;
};

// Step 1 of upload: vertices carrying their triangle's material, indices split by culling.
// A scene built in code may leave normals empty; its vertices then take the geometric normal
// of the first triangle using them (what parrender's shading uses in that case).
Mesh buildMesh(const scene::Scene& scene) {
  Mesh mesh;
  const size_t n = scene.positions.size();
  const bool haveNormals = scene.normals.size() == n;
  const glm::vec3 zero(0.0f);
  mesh.vertices.assign(n, Vertex{zero, zero, zero, zero});  // unreferenced vertices stay zero
  std::vector<uint32_t> materialOf(n, UINT32_MAX);  // material baked into vertex i (i < n)
  auto makeVertex = [&](uint32_t v, const scene::Triangle& t) {
    const scene::Material& m = scene.materials[t.material];
    glm::vec3 base = glm::vec3(m.baseColorFactor);
    if (scene.colors.size() == n) base *= glm::vec3(scene.colors[v]);
    glm::vec3 normal(0.0f, 0.0f, 1.0f);
    if (haveNormals) {
      normal = scene.normals[v];
    } else {
      const glm::vec3 p0 = scene.positions[t.v[0]], p1 = scene.positions[t.v[1]], p2 = scene.positions[t.v[2]];
      const glm::vec3 cross = glm::cross(p1 - p0, p2 - p0);
      if (glm::dot(cross, cross) > 0.0f) normal = glm::normalize(cross);
    }
    return Vertex{scene.positions[v], normal, base, m.emission()};
  };
  // Index of vertex v with t's material, duplicating v when another material claimed it.
  std::unordered_map<uint64_t, uint32_t> duplicates;  // (v << 32 | material) -> index
  auto vertexFor = [&](uint32_t v, const scene::Triangle& t) -> uint32_t {
    if (materialOf[v] == UINT32_MAX) {
      materialOf[v] = t.material;
      mesh.vertices[v] = makeVertex(v, t);
      return v;
    }
    if (materialOf[v] == t.material) return v;
    const uint64_t key = (uint64_t(v) << 32) | t.material;
    if (auto it = duplicates.find(key); it != duplicates.end()) return it->second;
    mesh.vertices.push_back(makeVertex(v, t));
    return duplicates[key] = uint32_t(mesh.vertices.size() - 1);
  };
  std::vector<uint32_t> doubleSided;
  mesh.indices.reserve(scene.triangles.size() * 3);
  for (const scene::Triangle& t : scene.triangles) {
    auto& out = scene.materials[t.material].doubleSided ? doubleSided : mesh.indices;
    for (uint32_t k = 0; k < 3; ++k) out.push_back(vertexFor(t.v[k], t));
  }
  mesh.singleSidedIndexCount = mesh.indices.size();
  mesh.indices.insert(mesh.indices.end(), doubleSided.begin(), doubleSided.end());
  return mesh;
}

constexpr const char* kVertexShader = R"(#version 300 es
layout(location = 0) in vec3 aPosition;
layout(location = 1) in vec3 aNormal;
layout(location = 2) in vec3 aBase;
layout(location = 3) in vec3 aEmission;
uniform mat4 uViewProjection;
out vec3 vPosition;
out vec3 vNormal;
out vec3 vBase;
out vec3 vEmission;
void main() {
  vPosition = aPosition;
  vNormal = aNormal;
  vBase = aBase;
  vEmission = aEmission;
  gl_Position = uViewProjection * vec4(aPosition, 1.0);
}
)";

// Radiance = emission + sum_lights base / pi * E * max(N.L, 0), E = I / d^2 for a point light
// and I for a directional one; with no lights the headlight gives base * max(N.V, 0) (pi lux
// from L = V, as the raster shade stage defines it). Clamped to [0, 1] for the RGBA8 target.
constexpr const char* kFragmentShader = R"(#version 300 es
precision highp float;
uniform int uLightCount;
uniform vec4 uLightPosition[2];   // w = 1: position of a point light; w = 0: direction towards the light
uniform vec3 uLightIntensity[2];  // colour * intensity
uniform vec4 uEye;                // w = 1: eye position; w = 0: direction towards the eye (orthographic)
in vec3 vPosition;
in vec3 vNormal;
in vec3 vBase;
in vec3 vEmission;
out vec4 fragColor;
void main() {
  vec3 n = normalize(vNormal);
  if (!gl_FrontFacing) n = -n;
  vec3 radiance = vEmission;
  if (uLightCount == 0) {
    vec3 v = uEye.w > 0.5 ? normalize(uEye.xyz - vPosition) : uEye.xyz;
    radiance += vBase * max(dot(n, v), 0.0);
  }
  for (int i = 0; i < uLightCount; ++i) {
    vec3 l = uLightPosition[i].xyz;
    vec3 e = uLightIntensity[i];
    if (uLightPosition[i].w > 0.5) {
      vec3 d = l - vPosition;
      float d2 = max(dot(d, d), 1e-12);
      l = d * inversesqrt(d2);
      e /= d2;
    }
    radiance += vBase * (0.31830988618 * max(dot(n, l), 0.0)) * e;
  }
  fragColor = vec4(min(radiance, vec3(1.0)), 1.0);
}
)";

GLuint compileShader(GLenum type, const char* source) {
  GLuint shader = glCreateShader(type);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[2048] = {};
    glGetShaderInfoLog(shader, sizeof log, nullptr, log);
    glDeleteShader(shader);
    throw std::runtime_error(std::string("llvmpipe anchor: shader compilation failed: ") + log);
  }
  return shader;
}

GLuint linkProgram() {
  GLuint vs = compileShader(GL_VERTEX_SHADER, kVertexShader);
  GLuint fs = compileShader(GL_FRAGMENT_SHADER, kFragmentShader);
  GLuint program = glCreateProgram();
  glAttachShader(program, vs);
  glAttachShader(program, fs);
  glLinkProgram(program);
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint ok = 0;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[2048] = {};
    glGetProgramInfoLog(program, sizeof log, nullptr, log);
    glDeleteProgram(program);
    throw std::runtime_error(std::string("llvmpipe anchor: program link failed: ") + log);
  }
  return program;
}

// Every GL object of one renderWithLlvmpipe call, deleted on the way out (also on throw).
struct GlObjects {
  GLuint program = 0, vao = 0, vbo = 0, ibo = 0, fbo = 0, colour = 0, depth = 0;
  ~GlObjects() {
    if (fbo) glDeleteFramebuffers(1, &fbo);
    GLuint renderbuffers[] = {colour, depth};
    glDeleteRenderbuffers(2, renderbuffers);
    GLuint buffers[] = {vbo, ibo};
    glDeleteBuffers(2, buffers);
    if (vao) glDeleteVertexArrays(1, &vao);
    if (program) glDeleteProgram(program);
  }
};

void setLights(GLuint program, const scene::Scene& scene, const scene::Camera& camera) {
  glm::vec4 position[2]{};
  glm::vec3 intensity[2]{};
  int count = 0;
  for (const scene::PunctualLight& light : scene.lights) {
    if (count == 2) break;
    if (light.type == scene::LightType::Directional)
      position[count] = glm::vec4(-light.direction, 0.0f);
    else
      position[count] = glm::vec4(light.position, 1.0f);  // spot cones are not modelled
    intensity[count] = light.color * light.intensity;
    ++count;
  }
  glUniform1i(glGetUniformLocation(program, "uLightCount"), count);
  glUniform4fv(glGetUniformLocation(program, "uLightPosition"), 2, glm::value_ptr(position[0]));
  glUniform3fv(glGetUniformLocation(program, "uLightIntensity"), 2, glm::value_ptr(intensity[0]));
  const glm::vec4 eye = camera.projection == scene::Projection::Perspective
                            ? glm::vec4(camera.position(), 1.0f)
                            : glm::vec4(glm::normalize(glm::vec3(camera.cameraToWorld[2])), 0.0f);  // +Z: towards the eye
  glUniform4fv(glGetUniformLocation(program, "uEye"), 1, glm::value_ptr(eye));
}

double processCpuMs() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return 1e3 * double(ts.tv_sec) + 1e-6 * double(ts.tv_nsec);
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

}  // namespace

RasterAnchorResult renderWithLlvmpipe(const scene::Scene& scene, const scene::Camera& camera, int width, int height,
                                      int threads, int frames) {
  if (width < 1 || width > 16384 || height < 1 || height > 16384)
    throw std::invalid_argument("llvmpipe anchor: image size " + std::to_string(width) + "x" + std::to_string(height) +
                                " outside [1, 16384]");
  if (frames < 1) throw std::invalid_argument("llvmpipe anchor: frames must be >= 1, got " + std::to_string(frames));
  EglContext& context = EglContext::acquire(threads);
  using Clock = std::chrono::steady_clock;
  RasterAnchorResult result;
  result.width = width;
  result.height = height;
  result.renderer = context.renderer();
  result.threads = context.threads();
  result.trianglesDrawn = scene.triangles.size();

  // Upload, once: program, vertex array, buffers, framebuffer.
  const auto uploadStart = Clock::now();
  const Mesh mesh = buildMesh(scene);
  GlObjects gl;
  gl.program = linkProgram();
  glGenVertexArrays(1, &gl.vao);
  glBindVertexArray(gl.vao);
  glGenBuffers(1, &gl.vbo);
  glBindBuffer(GL_ARRAY_BUFFER, gl.vbo);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(mesh.vertices.size() * sizeof(Vertex)), mesh.vertices.data(), GL_STATIC_DRAW);
  const size_t offsets[] = {offsetof(Vertex, position), offsetof(Vertex, normal), offsetof(Vertex, base),
                            offsetof(Vertex, emission)};
  for (GLuint a = 0; a < 4; ++a) {
    glEnableVertexAttribArray(a);
    glVertexAttribPointer(a, 3, GL_FLOAT, GL_FALSE, sizeof(Vertex), reinterpret_cast<const void*>(offsets[a]));
  }
  glGenBuffers(1, &gl.ibo);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, gl.ibo);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(mesh.indices.size() * sizeof(uint32_t)), mesh.indices.data(),
               GL_STATIC_DRAW);

  glGenRenderbuffers(1, &gl.colour);
  glBindRenderbuffer(GL_RENDERBUFFER, gl.colour);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width, height);
  glGenRenderbuffers(1, &gl.depth);
  glBindRenderbuffer(GL_RENDERBUFFER, gl.depth);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, width, height);
  glGenFramebuffers(1, &gl.fbo);
  glBindFramebuffer(GL_FRAMEBUFFER, gl.fbo);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, gl.colour);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, gl.depth);
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
    throw std::runtime_error("llvmpipe anchor: RGBA8 + DEPTH24 framebuffer of " + std::to_string(width) + "x" +
                             std::to_string(height) + " is incomplete");

  glUseProgram(gl.program);
  const float aspect = float(width) / float(height);
  const glm::mat4 viewProjection = camera.projectionMatrix(aspect) * camera.view();
  glUniformMatrix4fv(glGetUniformLocation(gl.program, "uViewProjection"), 1, GL_FALSE, glm::value_ptr(viewProjection));
  setLights(gl.program, scene, camera);
  glViewport(0, 0, width, height);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glCullFace(GL_BACK);
  glFrontFace(GL_CCW);
  glClearColor(0.0f, 0.0f, 0.0f, 0.0f);  // alpha 0 = not covered; every fragment writes alpha 1
  glClearDepthf(1.0f);
  glFinish();
  result.uploadMs = std::chrono::duration<double, std::milli>(Clock::now() - uploadStart).count();

  // One frame: clear, single-sided triangles culled, double-sided ones not, wait for the end.
  const auto drawFrame = [&] {
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    if (mesh.singleSidedIndexCount > 0) {
      glEnable(GL_CULL_FACE);
      glDrawElements(GL_TRIANGLES, GLsizei(mesh.singleSidedIndexCount), GL_UNSIGNED_INT, nullptr);
    }
    if (mesh.indices.size() > mesh.singleSidedIndexCount) {
      glDisable(GL_CULL_FACE);
      glDrawElements(GL_TRIANGLES, GLsizei(mesh.indices.size() - mesh.singleSidedIndexCount), GL_UNSIGNED_INT,
                     reinterpret_cast<const void*>(mesh.singleSidedIndexCount * sizeof(uint32_t)));
    }
    glFinish();
  };
  drawFrame();  // warm-up: llvmpipe compiles the shaders to machine code at the first draw
  result.frameMs.reserve(size_t(frames));
  result.frameCpuMs.reserve(size_t(frames));
  for (int f = 0; f < frames; ++f) {
    const auto start = Clock::now();
    const double cpuStart = processCpuMs();
    drawFrame();
    result.frameCpuMs.push_back(processCpuMs() - cpuStart);
    result.frameMs.push_back(std::chrono::duration<double, std::milli>(Clock::now() - start).count());
  }
  result.msPerFrameMedian = median(result.frameMs);
  result.cpuMsPerFrameMedian = median(result.frameCpuMs);
  if (GLenum error = glGetError(); error != GL_NO_ERROR)
    throw std::runtime_error("llvmpipe anchor: GL error " + std::to_string(error) + " while drawing");

  // Readback of the last frame, flipped so row 0 is the top row like pr::image::Image.
  std::vector<uint8_t> bottomUp(size_t(width) * size_t(height) * 4);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, bottomUp.data());
  const size_t rowBytes = size_t(width) * 4;
  result.rgba.resize(bottomUp.size());
  result.coverage.assign(size_t(width) * size_t(height), 0);
  for (int y = 0; y < height; ++y) {
    const uint8_t* src = bottomUp.data() + size_t(height - 1 - y) * rowBytes;
    std::copy(src, src + rowBytes, result.rgba.data() + size_t(y) * rowBytes);
    for (int x = 0; x < width; ++x)
      if (src[size_t(x) * 4 + 3] != 0) {
        result.coverage[size_t(y) * size_t(width) + size_t(x)] = 1;
        ++result.coveredPixels;
      }
  }
  return result;
}

}  // namespace pr::bench
