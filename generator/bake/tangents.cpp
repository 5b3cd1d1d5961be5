#include "bake/tangents.h"

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>

namespace sg::bake {
namespace {

glm::dvec3 d3(const Vec3& v) { return glm::dvec3(v[0], v[1], v[2]); }

// The angle of the triangle at corner a (between a->b and a->c); 0 for a degenerate corner.
double cornerAngle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
  glm::dvec3 u = b - a, v = c - a;
  double lu = glm::length(u), lv = glm::length(v);
  if (lu == 0 || lv == 0) return 0;
  return std::acos(std::clamp(glm::dot(u, v) / (lu * lv), -1.0, 1.0));
}

}  // namespace

TangentResult bakeTangents(const std::vector<Vec3>& positions, const std::vector<Vec3>& normals,
                           const std::vector<Vec2>& uvs, const std::vector<std::array<uint32_t, 3>>& triangles) {
  const size_t n = positions.size();
  std::vector<glm::dvec3> sumU(n, glm::dvec3(0.0)), sumV(n, glm::dvec3(0.0));
  for (const auto& t : triangles) {
    glm::dvec3 p[3] = {d3(positions[t[0]]), d3(positions[t[1]]), d3(positions[t[2]])};
    glm::dvec2 w[3] = {{uvs[t[0]][0], uvs[t[0]][1]}, {uvs[t[1]][0], uvs[t[1]][1]}, {uvs[t[2]][0], uvs[t[2]][1]}};
    glm::dvec3 e1 = p[1] - p[0], e2 = p[2] - p[0];
    glm::dvec2 s1 = w[1] - w[0], s2 = w[2] - w[0];
    // Solve [e1 e2] = [dP/du dP/dv] [s1 s2] for the two derivatives.
    double det = s1.x * s2.y - s2.x * s1.y;
    if (!(std::fabs(det) > 1e-20)) continue;  // UVs collapse to a line or a point (or NaN)
    glm::dvec3 dPdu = (e1 * s2.y - e2 * s1.y) / det, dPdv = (e2 * s1.x - e1 * s2.x) / det;
    if (!std::isfinite(glm::dot(dPdu, dPdu)) || !std::isfinite(glm::dot(dPdv, dPdv))) continue;
    // Only directions are wanted: unit per triangle, then weighted by the corner angle.
    double lu = glm::length(dPdu), lv = glm::length(dPdv);
    if (lu == 0 || lv == 0) continue;
    dPdu /= lu;
    dPdv /= lv;
    for (int k = 0; k < 3; ++k) {
      double a = cornerAngle(p[k], p[(k + 1) % 3], p[(k + 2) % 3]);
      if (!(a > 0)) continue;  // a degenerate corner (or NaN positions) adds nothing
      sumU[t[k]] += a * dPdu;
      sumV[t[k]] += a * dPdv;
    }
  }
  TangentResult r;
  r.tangents.resize(n);
  for (size_t v = 0; v < n; ++v) {
    glm::dvec3 nv = d3(normals[v]);
    double ln = glm::length(nv);
    if (!(ln > 0) || !std::isfinite(ln)) {
      r.tangents[v] = {0, 0, 0, 1};
      continue;
    }
    nv /= ln;
    glm::dvec3 t = sumU[v] - glm::dot(sumU[v], nv) * nv;
    double lt = glm::length(t);
    glm::dvec3 bt = glm::cross(nv, t);
    double w = glm::dot(bt, sumV[v]) < 0 ? -1.0 : 1.0;
    if (lt > 1e-12 * (glm::length(sumU[v]) + 1e-300) && lt > 0) {
      t /= lt;
    } else {
      Vec3 bt3, b3;
      orthonormalBasis({static_cast<float>(nv.x), static_cast<float>(nv.y), static_cast<float>(nv.z)}, bt3, b3);
      t = d3(bt3);
      w = 1.0;
      ++r.fallbacks;
    }
    r.tangents[v] = {static_cast<float>(t.x), static_cast<float>(t.y), static_cast<float>(t.z), static_cast<float>(w)};
  }
  return r;
}

}  // namespace sg::bake
