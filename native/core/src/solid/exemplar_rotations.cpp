#include "solid/exemplar_rotations.hpp"

#include <algorithm>

namespace exsynth::solid {

Image quarter_turn_mosaic(const Image& ex) {
  const int s = std::min(ex.width(), ex.height()), c = ex.channels();
  const int x0 = (ex.width() - s) / 2, y0 = (ex.height() - s) / 2;  // the central square
  Image out(2 * s, 2 * s, c);
  // Quarter q at (qx, qy) turned q x 90 degrees clockwise: its pixel (x, y)
  // is the square's pixel at the inverse turn of (x, y).
  for (int q = 0; q < 4; ++q) {
    const int qx = (q & 1) * s, qy = (q >> 1) * s;
    for (int y = 0; y < s; ++y)
      for (int x = 0; x < s; ++x) {
        int sx = x, sy = y;
        for (int t = 0; t < q; ++t) {  // undo one clockwise turn: (x, y) <- (y, s - 1 - x)
          const int nx = sy, ny = s - 1 - sx;
          sx = nx;
          sy = ny;
        }
        std::copy_n(ex.data() + ex.offset(x0 + sx, y0 + sy), c, out.data() + out.offset(qx + x, qy + y));
      }
  }
  return out;
}

}  // namespace exsynth::solid
