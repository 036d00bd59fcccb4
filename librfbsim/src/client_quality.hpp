// SPDX-License-Identifier: GPL-2.0-or-later
// ClientQualityRequest: the JPEG quality, subsampling and compression a Tight client asked for, and how it
// lowers the server's own top quality for that client.
//
// Clients name these through pseudo-encodings in SetEncodings: quality levels 0..9 (-32..-23, TightVNC and
// TigerVNC, noVNC's ?quality=), TurboVNC's fine quality 1..100 (-512..-412) and subsampling (-768..-765), and
// compress levels 0..9 (-256..-247). libvncserver 0.9.14 parses them into rfbClientRec (a level becomes a JPEG
// quality and a subsampling through the table TigerVNC's server uses: level 6 is quality 79 at 4:4:4, level 3 is
// 42 at 4:2:2), and resets them at each SetEncodings; the server's hooks copy that result here.
//
// The rule: the client's request is the top of its adaptive ladder, never above the server's --jpeg-quality and
// subsampling (the operator's budget for the host's uplink). So a client can ask for less than the server sends
// (a viewer on a slow link, TigerVNC's -QualityLevel), never for more. TigerVNC's own server takes the client's
// level as it is; ours keeps a cap because one host serves many participants. Pure: no sockets, no libvncserver.
#pragma once

#include "adaptive_quality.hpp"

namespace rfbsim::detail {

/// What one client asked for, as libvncserver parsed its latest SetEncodings.
struct ClientQualityRequest {
  int quality_level = -1;   ///< Tight quality level 0..9 (rfbClientRec::tightQualityLevel); -1 = none asked
  int jpeg_quality = -1;    ///< JPEG quality 1..100 from that level or the fine level (turboQualityLevel); -1 = none
  int subsampling = 0;      ///< libvncserver's index (turboSubsampLevel): 0 = 4:4:4 (also when none asked), 1 = 4:2:0,
                            ///< 2 = 4:2:2, 3 = grey
  int compress_level = 6;   ///< zlib level 0..9 (tightCompressLevel); libvncserver's default 6 when none asked
  bool operator==(const ClientQualityRequest&) const = default;
};

/// How much colour detail subsampling index `index` drops: 0 for 4:4:4, 1 for 4:2:2, 2 for 4:2:0, 3 for grey
/// (an unknown index counts as 4:2:0).
int subsampling_coarseness(int index);

/// `level` lowered to what `request` asked for: the lower of the two JPEG qualities (a request of none or out of
/// 1..100 leaves it) and the coarser of the two subsamplings. Never raises either.
QualityLevel capped_by_client(const QualityLevel& level, const ClientQualityRequest& request);

}  // namespace rfbsim::detail
