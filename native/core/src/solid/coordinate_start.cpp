#include "solid/coordinate_start.hpp"

#include <cmath>

#include "exsynth/pyramid.hpp"
#include "solid/coordinate_synthesis.hpp"

namespace exsynth::solid {

Volume coordinate_start_texture(const std::array<const Image*, 3>& views, const SolidOptions& opt, int halvings,
                                int exponent, ExecContext* ctx) {
  SolidOptions copt = opt;
  copt.method = SolidMethod::Coordinates;
  copt.coordinate_start = 0;
  // A private context: the coordinates synthesis reports progress 0..1 of
  // its own, which would move the optimiser's bar backwards; cancelling is
  // forwarded.
  ExecContext sub;
  if (ctx) sub.on_check([ctx] { ctx->check(); });
  Volume tex = synthesize_coordinates(views, Volume{}, copt, ctx ? &sub : nullptr).texture;
  const Boundary b = opt.tileable ? Boundary::Wrap : Boundary::Clamp;
  for (int h = 0; h < halvings; ++h) tex = downsample(tex, b);
  if (exponent != 0)
    for (float& v : tex.values()) v = std::ldexp(v, -exponent);
  return tex;
}

}  // namespace exsynth::solid
