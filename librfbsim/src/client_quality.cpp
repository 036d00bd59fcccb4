// SPDX-License-Identifier: GPL-2.0-or-later
// ClientQualityRequest: a client's own quality request as a cap on the server's.
#include "client_quality.hpp"

#include <algorithm>

namespace rfbsim::detail {

int subsampling_coarseness(int index) {
  switch (index) {
    case 0: return 0;  // 4:4:4
    case 2: return 1;  // 4:2:2: half the chroma columns
    case 3: return 3;  // grey: no chroma at all
    default: return 2;  // 4:2:0, and anything we do not know: what the server's default already is
  }
}

QualityLevel capped_by_client(const QualityLevel& level, const ClientQualityRequest& request) {
  QualityLevel capped = level;
  if (request.jpeg_quality >= 1 && request.jpeg_quality <= 100) {
    capped.jpeg_quality = std::min(level.jpeg_quality, request.jpeg_quality);
  }
  // Only the four indices libvncserver's Tight encoder knows are ever handed on to it.
  const bool known = request.subsampling >= 0 && request.subsampling <= 3;
  if (known && subsampling_coarseness(request.subsampling) > subsampling_coarseness(level.subsampling)) {
    capped.subsampling = request.subsampling;
  }
  return capped;
}

}  // namespace rfbsim::detail
