#include "harness/window/mesh_tiles_view.hpp"

#include <epoxy/gl.h>

namespace sb {

MeshTileSurface::MeshTileSurface(std::size_t tiles, const Vec3& offset)
    : offset_(offset), vaos_(tiles), vbos_(tiles), vertices_(tiles, 0) {
  const auto n = static_cast<GLsizei>(tiles);
  glGenVertexArrays(n, vaos_.data());
  glGenBuffers(n, vbos_.data());
  for (std::size_t t = 0; t < tiles; ++t) {
    glBindVertexArray(vaos_[t]);
    glBindBuffer(GL_ARRAY_BUFFER, vbos_[t]);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), nullptr);
  }
  glBindVertexArray(0);
}

MeshTileSurface::~MeshTileSurface() {
  glDeleteBuffers(static_cast<GLsizei>(vbos_.size()), vbos_.data());
  glDeleteVertexArrays(static_cast<GLsizei>(vaos_.size()), vaos_.data());
}

void MeshTileSurface::upload(const MeshTileUpdate& u) {
  const bool shift = offset_ != Vec3::Zero();
  for (std::size_t k = 0; k < u.tiles.size(); ++k) {
    const std::size_t t = u.tiles[k];
    if (t >= vbos_.size()) continue;
    const float* data = u.xyz.data() + u.offsets[k];
    const std::size_t floats = u.offsets[k + 1] - u.offsets[k];
    if (shift) {
      shifted_.assign(data, data + floats);
      for (std::size_t i = 0; i < floats; ++i)
        shifted_[i] += static_cast<float>(offset_[static_cast<Eigen::Index>(i % 3)]);
      data = shifted_.data();
    }
    glBindBuffer(GL_ARRAY_BUFFER, vbos_[t]);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(floats * sizeof(float)), data, GL_DYNAMIC_DRAW);
    vertices_[t] = static_cast<int>(floats / 3);
  }
  glBindBuffer(GL_ARRAY_BUFFER, 0);
}

void MeshTileSurface::draw() const {
  for (std::size_t t = 0; t < vaos_.size(); ++t) {
    if (vertices_[t] == 0) continue;
    glBindVertexArray(vaos_[t]);
    glDrawArrays(GL_TRIANGLES, 0, vertices_[t]);
  }
}

}  // namespace sb
