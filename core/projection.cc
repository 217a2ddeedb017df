#include "core/projection.h"

#include <algorithm>

#include "core/check.h"
#include "core/look_at.h"

namespace core {

glm::mat4 ClipFromCamPerspective(double fx, double fy, double cx, double cy, int width, int height,
                                 double near, double far) {
  IBR_CHECK(width > 0 && height > 0 && near > 0 && far > near);
  // x_ndc = 2u/W - 1 = (2 fx X/Z + 2 cx)/W - 1  ->  clip x = (2fx/W) X + (2cx/W - 1) Z, w = Z.
  // y_ndc = 1 - 2v/H                            ->  clip y = -(2fy/H) Y + (1 - 2cy/H) Z.
  glm::dmat4 m(0.0);  // column-major: m[col][row]
  m[0][0] = 2 * fx / width;
  m[2][0] = 2 * cx / width - 1;
  m[1][1] = -2 * fy / height;
  m[2][1] = 1 - 2 * cy / height;
  m[2][2] = (far + near) / (far - near);
  m[3][2] = -2 * far * near / (far - near);
  m[2][3] = 1;
  return glm::mat4(m);
}

glm::mat4 ClipFromCamOrthographic(double sx, double sy, double cx, double cy, int width, int height,
                                  double near, double far) {
  IBR_CHECK(width > 0 && height > 0 && far > near);
  glm::dmat4 m(0.0);
  m[0][0] = 2 * sx / width;
  m[3][0] = 2 * cx / width - 1;
  m[1][1] = -2 * sy / height;
  m[3][1] = 1 - 2 * cy / height;
  m[2][2] = 2 / (far - near);
  m[3][2] = -(far + near) / (far - near);
  m[3][3] = 1;
  return glm::mat4(m);
}

glm::dvec2 ClipRangeZ(const glm::mat4& p) {
  glm::dvec2 z;
  for (int i = 0; i < 2; ++i) {
    const double ndc = i == 0 ? -1.0 : 1.0;
    z[i] = (double(p[3][2]) - ndc * p[3][3]) / (ndc * p[2][3] - p[2][2]);
  }
  return {std::min(z.x, z.y), std::max(z.x, z.y)};
}

glm::dmat4 CamFromWorldLookAtDouble(const glm::dvec3& eye, const glm::dvec3& target,
                                    const glm::dvec3& up) {
  const glm::dvec3 z = glm::normalize(target - eye);
  glm::dvec3 x = glm::cross(z, up);  // camera x = y x z with y = -up
  if (glm::dot(x, x) < 1e-20) x = glm::cross(z, glm::dvec3(1, 0, 0));
  if (glm::dot(x, x) < 1e-20) x = glm::cross(z, glm::dvec3(0, 1, 0));
  x = glm::normalize(x);
  const glm::dvec3 y = glm::cross(z, x);
  glm::dmat4 m(1.0);
  for (int c = 0; c < 3; ++c) {
    m[c][0] = x[c];
    m[c][1] = y[c];
    m[c][2] = z[c];
  }
  m[3][0] = -glm::dot(x, eye);
  m[3][1] = -glm::dot(y, eye);
  m[3][2] = -glm::dot(z, eye);
  return m;
}

glm::mat4 CamFromWorldLookAt(glm::vec3 eye, glm::vec3 target, glm::vec3 up) {
  return glm::mat4(CamFromWorldLookAtDouble(glm::dvec3(eye), glm::dvec3(target), glm::dvec3(up)));
}

}  // namespace core
