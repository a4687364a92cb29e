#include "panmap/render/renderer.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "panmap/core/error.h"

namespace panmap {

namespace {

// Faces per culling run: meshes are written object by object, so a run of consecutive faces
// is spatially compact; small enough to cull a room's far half, large enough that testing the
// runs costs nothing next to drawing.
constexpr int32_t kRunFaces = 512;

}  // namespace

void RenderConfig::check() const {
  if (!(near_m > 0.0f)) throw Error("render near_m must be > 0");
  if (!(far_m > near_m)) throw Error("render far_m must exceed near_m");
  if (!(ambient >= 0.0f && ambient <= 1.0f)) throw Error("render ambient must be in [0, 1]");
  if (!(texture_cell_m > 0.0f)) throw Error("render texture_cell_m must be > 0");
  if (std::isnan(max_face_height_m)) throw Error("render max_face_height_m must be a number");
  if (!(texture_contrast >= 0.0f && texture_contrast <= 1.0f)) {
    throw Error("render texture_contrast must be in [0, 1]");
  }
}

// Per-frame working memory: vertices in the camera frame and the z-buffer.
struct MeshRenderer::Scratch {
  std::vector<Eigen::Vector3f> points_C;
  Image<float> zbuffer;  // z of the nearest surface so far
  Image<int32_t> face;   // its face index, -1 = none
};

MeshRenderer::MeshRenderer(const LabelledMesh& mesh, const RenderConfig& config)
    : MeshRenderer(std::make_shared<const LabelledMesh>(mesh), config) {}

MeshRenderer::MeshRenderer(LabelledMesh&& mesh, const RenderConfig& config)
    : MeshRenderer(std::make_shared<const LabelledMesh>(std::move(mesh)), config) {}

MeshRenderer::MeshRenderer(std::shared_ptr<const LabelledMesh> shared, const RenderConfig& config)
    : mesh_(std::move(shared)), config_(config) {
  config_.check();
  if (!mesh_) throw Error("renderer: no mesh");
  const LabelledMesh& mesh = *mesh_;
  const std::string problem = mesh.check();
  if (!problem.empty()) throw Error("renderer: mesh is inconsistent: " + problem);
  const size_t n = mesh.faces.size();
  // A face takes its first vertex's labels and colour: copied per face for speed (the simulator
  // renders thousands of frames), or read through the mesh (an overview of a whole map, once).
  if (config_.keep_face_data) {
    face_normals_W_.resize(n);
    if (!mesh.instance.empty()) face_instance_.resize(n);
    if (!mesh.semantic.empty()) face_semantic_.resize(n);
    if (!mesh.colors.empty()) face_color_.resize(n);
    for (size_t f = 0; f < n; ++f) {
      const int32_t first = mesh.faces[f][0];
      face_normals_W_[f] = faceNormal(static_cast<int32_t>(f));
      if (!mesh.instance.empty()) face_instance_[f] = mesh.instance[first];
      if (!mesh.semantic.empty()) face_semantic_[f] = mesh.semantic[first];
      if (!mesh.colors.empty()) face_color_[f] = mesh.colors[first];
    }
  }
  for (size_t first = 0; first < n; first += kRunFaces) {
    FaceRun run;
    run.first_face = static_cast<int32_t>(first);
    run.end_face = static_cast<int32_t>(std::min(n, first + kRunFaces));
    run.first_vertex = std::numeric_limits<int32_t>::max();
    run.end_vertex = 0;
    for (int32_t f = run.first_face; f < run.end_face; ++f) {
      for (int k = 0; k < 3; ++k) {
        const int32_t v = mesh.faces[f][k];
        run.box_W.extend(mesh.vertices[v]);
        run.first_vertex = std::min(run.first_vertex, v);
        run.end_vertex = std::max(run.end_vertex, v + 1);
      }
    }
    runs_.push_back(run);
  }
}

Eigen::Vector3f MeshRenderer::faceNormal(int32_t f) const {
  const LabelledMesh& mesh = *mesh_;
  const Eigen::Vector3i& t = mesh.faces[f];
  const Eigen::Vector3f e1 = mesh.vertices[t[1]] - mesh.vertices[t[0]];
  const Eigen::Vector3f e2 = mesh.vertices[t[2]] - mesh.vertices[t[0]];
  return e1.cross(e2).normalized();
}

RenderedView MeshRenderer::render(const PinholeCamera& camera,
                                  const Eigen::Isometry3d& T_W_C) const {
  RenderedView view;
  render(camera, T_W_C, &view);
  return view;
}

namespace {

// Draws one triangle given in the camera frame, all corners at z >= near. Setup runs in double
// so that large triangles projecting far off-screen keep sub-millimetre depth.
inline void drawTriangle(const PinholeCamera& cam, const Eigen::Vector3f& af,
                         const Eigen::Vector3f& bf, const Eigen::Vector3f& cf, int32_t face,
                         Image<float>* zbuffer, Image<int32_t>* faces) {
  const Eigen::Vector3d a = af.cast<double>(), b = bf.cast<double>(), c = cf.cast<double>();
  const double ua = cam.fx * a.x() / a.z() + cam.cx, va = cam.fy * a.y() / a.z() + cam.cy;
  const double ub = cam.fx * b.x() / b.z() + cam.cx, vb = cam.fy * b.y() / b.z() + cam.cy;
  const double uc = cam.fx * c.x() / c.z() + cam.cx, vc = cam.fy * c.y() / c.z() + cam.cy;
  // Signed double area; either winding is drawn.
  const double area = (ub - ua) * (vc - va) - (vb - va) * (uc - ua);
  if (std::abs(area) < 1e-12 || !std::isfinite(area)) return;
  const int u0 = std::max(0, static_cast<int>(std::ceil(std::min({ua, ub, uc}))));
  const int u1 = std::min(cam.width - 1, static_cast<int>(std::floor(std::max({ua, ub, uc}))));
  const int v0 = std::max(0, static_cast<int>(std::ceil(std::min({va, vb, vc}))));
  const int v1 = std::min(cam.height - 1, static_cast<int>(std::floor(std::max({va, vb, vc}))));
  if (u0 > u1 || v0 > v1) return;
  // 1/z of the triangle's plane n . p = d along the ray ((u - cx) / fx, (v - cy) / fy, 1) is
  // linear in (u, v): exact perspective-correct depth.
  const Eigen::Vector3d n = (b - a).cross(c - a);
  const double d = n.dot(a);
  if (std::abs(d) < 1e-12) return;  // seen edge-on
  const double iz_du = n.x() / (cam.fx * d), iz_dv = n.y() / (cam.fy * d);
  const double iz_0 = (n.z() - n.x() * cam.cx / cam.fx - n.y() * cam.cy / cam.fy) / d;
  // Edge functions, normalised barycentrics of corners a and b: evaluated exactly at each
  // row start, stepped along the row.
  const double inv_area = 1.0 / area;
  const double wa_du = -(vc - vb) * inv_area;
  const double wb_du = -(va - vc) * inv_area;
  const double eps = -1e-6;  // closes seams between neighbouring triangles
  for (int v = v0; v <= v1; ++v) {
    double wa = ((ub - u0) * (vc - v) - (vb - v) * (uc - u0)) * inv_area;
    double wb = ((uc - u0) * (va - v) - (vc - v) * (ua - u0)) * inv_area;
    double iz = iz_0 + iz_du * u0 + iz_dv * v;
    float* zrow = zbuffer->row(v);
    int32_t* frow = faces->row(v);
    for (int u = u0; u <= u1; ++u, wa += wa_du, wb += wb_du, iz += iz_du) {
      if (wa < eps || wb < eps || 1.0 - wa - wb < eps) continue;
      const float z = static_cast<float>(1.0 / iz);
      if (z < zrow[u]) {
        zrow[u] = z;
        frow[u] = face;
      }
    }
  }
}

}  // namespace

std::vector<const MeshRenderer::FaceRun*> MeshRenderer::visibleRuns(
    const PinholeCamera& camera, const Eigen::Isometry3f& T_C_W) const {
  // Half-spaces of the frustum in the camera frame, a . p + b z > 0 inside: a point of a face
  // drawn at z >= near outside one of them projects beside the image, so a run whose eight
  // corners are all outside one draws nothing (the clipped corners are convex combinations).
  // One pixel of margin absorbs float rounding against drawTriangle's double setup.
  const float fx = static_cast<float>(camera.fx), fy = static_cast<float>(camera.fy);
  const float cx = static_cast<float>(camera.cx), cy = static_cast<float>(camera.cy);
  const float right = static_cast<float>(camera.width - 1) + 1.0f - cx;
  const float bottom = static_cast<float>(camera.height - 1) + 1.0f - cy;
  std::vector<const FaceRun*> visible;
  for (const FaceRun& run : runs_) {
    if (!config_.cull) {
      visible.push_back(&run);
      continue;
    }
    bool behind = true, beyond = true, left = true, over_right = true, above = true, below = true;
    for (int c = 0; c < 8; ++c) {
      const Eigen::Vector3f p =
          T_C_W * run.box_W.corner(static_cast<Eigen::AlignedBox3f::CornerType>(c));
      behind = behind && p.z() < config_.near_m;
      beyond = beyond && p.z() > config_.far_m;
      left = left && fx * p.x() + (cx + 1.0f) * p.z() < 0.0f;
      over_right = over_right && fx * p.x() - right * p.z() > 0.0f;
      above = above && fy * p.y() + (cy + 1.0f) * p.z() < 0.0f;
      below = below && fy * p.y() - bottom * p.z() > 0.0f;
    }
    if (!(behind || beyond || left || over_right || above || below)) visible.push_back(&run);
  }
  return visible;
}

void MeshRenderer::rasterise(const PinholeCamera& camera, const Eigen::Isometry3d& T_W_C,
                             Scratch* s) const {
  const Eigen::Isometry3f T_C_W = T_W_C.inverse().cast<float>();
  const std::vector<const FaceRun*> runs = visibleRuns(camera, T_C_W);
  // Transform the vertices the visible runs use: the union of their index ranges.
  const std::vector<Eigen::Vector3f>& vertices = mesh_->vertices;
  s->points_C.resize(vertices.size());
  std::vector<std::pair<int32_t, int32_t>> ranges;
  for (const FaceRun* run : runs) ranges.push_back({run->first_vertex, run->end_vertex});
  std::sort(ranges.begin(), ranges.end());
  int32_t done = 0;
  for (const auto& [first, end] : ranges) {
    for (int32_t i = std::max(first, done); i < end; ++i) s->points_C[i] = T_C_W * vertices[i];
    done = std::max(done, end);
  }
  const float near = config_.near_m;
  const float far = config_.far_m;
  for (const FaceRun* run : runs) {
    for (int32_t f = run->first_face; f < run->end_face; ++f) {
      drawFace(camera, f, near, far, s);
    }
  }
}

void MeshRenderer::drawFace(const PinholeCamera& camera, int32_t f, float near, float far,
                            Scratch* s) const {
  const Eigen::Vector3i& t = mesh_->faces[f];
  if (config_.max_face_height_m < std::numeric_limits<float>::infinity()) {
    const std::vector<Eigen::Vector3f>& v = mesh_->vertices;
    const float top = config_.max_face_height_m;
    if (v[t[0]].z() > top && v[t[1]].z() > top && v[t[2]].z() > top) return;
  }
  const Eigen::Vector3f* p[3] = {&s->points_C[t[0]], &s->points_C[t[1]], &s->points_C[t[2]]};
  const int in_front = (p[0]->z() >= near) + (p[1]->z() >= near) + (p[2]->z() >= near);
  if (in_front == 0) return;
  if (p[0]->z() > far && p[1]->z() > far && p[2]->z() > far) return;
  const auto id = static_cast<int32_t>(f);
  if (in_front == 3) {
    drawTriangle(camera, *p[0], *p[1], *p[2], id, &s->zbuffer, &s->face);
    return;
  }
  // Clip the polygon against z = near (Sutherland-Hodgman, one plane): 3 or 4 corners.
  Eigen::Vector3f poly[4];
  int n = 0;
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3f& cur = *p[k];
    const Eigen::Vector3f& nxt = *p[(k + 1) % 3];
    const bool cur_in = cur.z() >= near, nxt_in = nxt.z() >= near;
    if (cur_in) poly[n++] = cur;
    if (cur_in != nxt_in) {
      const float s_t = (near - cur.z()) / (nxt.z() - cur.z());
      poly[n++] = cur + s_t * (nxt - cur);
      poly[n - 1].z() = near;
    }
  }
  for (int k = 1; k + 1 < n; ++k) {
    drawTriangle(camera, poly[0], poly[k], poly[k + 1], id, &s->zbuffer, &s->face);
  }
}

MeshRenderer::Scratch& MeshRenderer::rasteriseView(const PinholeCamera& camera,
                                                   const Eigen::Isometry3d& T_W_C) const {
  std::string why;
  if (!camera.isValid(&why)) throw Error("renderer: camera: " + why);
  thread_local Scratch scratch;
  const int w = camera.width, h = camera.height;
  if (scratch.zbuffer.width() != w || scratch.zbuffer.height() != h) {
    scratch.zbuffer = Image<float>(w, h);
    scratch.face = Image<int32_t>(w, h);
  }
  std::fill(scratch.zbuffer.data(), scratch.zbuffer.data() + scratch.zbuffer.size(),
            std::numeric_limits<float>::infinity());
  std::fill(scratch.face.data(), scratch.face.data() + scratch.face.size(), -1);
  rasterise(camera, T_W_C, &scratch);
  return scratch;
}

void MeshRenderer::renderFaces(const PinholeCamera& camera, const Eigen::Isometry3d& T_W_C,
                               Image<int32_t>* face, Image<float>* cos_incidence) const {
  Scratch& scratch = rasteriseView(camera, T_W_C);
  const int w = camera.width, h = camera.height;
  *face = scratch.face;
  if (cos_incidence->width() != w || cos_incidence->height() != h) {
    *cos_incidence = Image<float>(w, h);
  }
  const Eigen::Matrix3f R_W_C = T_W_C.linear().cast<float>();
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const int32_t f = scratch.face(u, v);
      if (f < 0) {
        (*cos_incidence)(u, v) = 0.0f;
        continue;
      }
      const Eigen::Vector3f ray_C(
          (u - static_cast<float>(camera.cx)) / static_cast<float>(camera.fx),
          (v - static_cast<float>(camera.cy)) / static_cast<float>(camera.fy), 1.0f);
      (*cos_incidence)(u, v) = cosIncidence(f, R_W_C * ray_C.normalized());
    }
  }
}

void MeshRenderer::render(const PinholeCamera& camera, const Eigen::Isometry3d& T_W_C,
                          RenderedView* view) const {
  Scratch& scratch = rasteriseView(camera, T_W_C);
  const int w = camera.width, h = camera.height;

  if (view->depth_m.width() != w || view->depth_m.height() != h) {
    view->depth_m = Image<float>(w, h);
    view->color = ColorImage(w, h);
    view->instance = LabelImage(w, h);
    view->semantic = LabelImage(w, h);
    view->cos_incidence = Image<float>(w, h);
  }
  const Eigen::Matrix3f R_W_C = T_W_C.linear().cast<float>();
  const Eigen::Vector3f t_W_C = T_W_C.translation().cast<float>();
  const float two_pi_over_cell = 6.2831853f / config_.texture_cell_m;
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const int32_t f = scratch.face(u, v);
      if (f < 0) {
        view->depth_m(u, v) = 0.0f;
        view->color(u, v) = Rgb8{0, 0, 0};
        view->instance(u, v) = 0;
        view->semantic(u, v) = 0;
        view->cos_incidence(u, v) = 0.0f;
        continue;
      }
      const float z = scratch.zbuffer(u, v);
      const Eigen::Vector3f ray_C(
          (u - static_cast<float>(camera.cx)) / static_cast<float>(camera.fx),
          (v - static_cast<float>(camera.cy)) / static_cast<float>(camera.fy), 1.0f);
      const float cos_i = cosIncidence(f, R_W_C * ray_C.normalized());
      view->depth_m(u, v) = z;
      // A face's labels and colour: its own copies, or its first vertex's in the mesh.
      int32_t instance = 0, semantic = 0;
      Rgb8 base{180, 180, 180};
      if (config_.keep_face_data) {
        if (!face_instance_.empty()) instance = face_instance_[f];
        if (!face_semantic_.empty()) semantic = face_semantic_[f];
        if (!face_color_.empty()) base = face_color_[f];
      } else {
        const LabelledMesh& mesh = *mesh_;
        const int32_t first = mesh.faces[f][0];
        if (!mesh.instance.empty()) instance = mesh.instance[first];
        if (!mesh.semantic.empty()) semantic = mesh.semantic[first];
        if (!mesh.colors.empty()) base = mesh.colors[first];
      }
      view->instance(u, v) = instance;
      view->semantic(u, v) = semantic;
      view->cos_incidence(u, v) = cos_i;
      // Headlight shading times a 3D sine texture whose phase depends on the instance, so
      // colour carries surface information a network or a photometric term could use.
      const Eigen::Vector3f p_W = R_W_C * (ray_C * z) + t_W_C;
      const float phase = 0.7f * static_cast<float>(instance % 7);
      const float pattern = std::sin(two_pi_over_cell * p_W.x() + phase) *
                            std::sin(two_pi_over_cell * p_W.y() + 2.0f * phase) *
                            std::sin(two_pi_over_cell * p_W.z() + 3.0f * phase);
      const float shade = (config_.ambient + (1.0f - config_.ambient) * cos_i) *
                          (1.0f - config_.texture_contrast * (0.5f + 0.5f * pattern));
      view->color(u, v) = shadedColour(base, shade);
    }
  }
}

}  // namespace panmap
