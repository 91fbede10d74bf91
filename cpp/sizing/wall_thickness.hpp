// The local thickness of the domain behind its boundary samples: from a sample, straight into
// the domain (against its outward normal), how far away the boundary on the other side of the
// wall is. The sizing uses it where a curved wall is thin (sizing/sizing_parameters.hpp,
// thinWall): a chord's sagitta that is small against the curvature radius can still be large
// against the wall, and an element spanning the wall then folds when it is curved.
#pragma once

#include <vector>

#include "core/parameters.hpp"
#include "sizing/boundary_sampling.hpp"
#include "sizing/sizing_parameters.hpp"

namespace homesh {

// For each sample i with an outward normal and reach[i] > 0: the smallest a = (q - p) . n over
// the samples q that lie within a cone of half-angle 30 degrees around n (n = -outward of p,
// widened by half of q's spacing, so a wall sampled more coarsely is not missed between its
// samples), with 0 < a <= reach[i] and q's outward normal within 60 degrees of n (the far side
// of the wall faces away from p). Infinity where no sample qualifies, for samples without an
// outward normal, internal ones (between two solids: no wall) and those with reach[i] <= 0;
// internal samples are never the far side either.
// Uses up to `threads` threads; the result does not depend on their number.
std::vector<double> wallThickness(const std::vector<BoundarySample>& samples,
                                  const std::vector<double>& reach,
                                  int threads = defaultOf<int>("threads"));

// The thin-wall bound of the sizing (SizingParameters::thinWall): at each curved wall sample of
// radius R = 1 / curvature and thickness t, the size becomes the chord whose sagitta is
// thinWall t where that is below the sample's size (maxDelta where it has none), and at least
// a third of that size and minDelta (a wall thinning out to nothing would otherwise ask for
// minDelta all along). The thickness is searched only as far as it could change a size. Returns how
// many samples it made smaller; with thinWall 0, none.
std::size_t applyThinWallSizes(std::vector<BoundarySample>& samples, const SizingParameters& params,
                               int threads = defaultOf<int>("threads"));

}  // namespace homesh
