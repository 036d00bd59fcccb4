// SPDX-License-Identifier: GPL-2.0-or-later
// Provenance: the log's versions against this build and the files.
#include "replay/provenance.hpp"

namespace rfbsim::replay {

std::vector<ProvenanceMismatch> build_mismatches(const sim::SessionMeta& meta, const std::string& version,
                                                 const std::string& build) {
  std::vector<ProvenanceMismatch> found;
  if (meta.rfbsim_version != version) {
    found.push_back({"versions.rfbsim", meta.rfbsim_version, version, "recorded by another rfbsim version"});
  }
  if (meta.build != build) {
    found.push_back({"versions.build", meta.build, build,
                     "recorded by another build (compiler or build type): floating point may round differently"});
  }
  return found;
}

std::vector<ProvenanceMismatch> file_mismatches(const sim::SessionMeta& meta, const sim::SessionInfo& now) {
  std::vector<ProvenanceMismatch> found;
  if (meta.scenario_sha256 != now.scenario_sha256) {
    found.push_back({"versions.scenario_sha256", meta.scenario_sha256, now.scenario_sha256,
                     "the scenario file " + now.scenario_file + " changed since the recording"});
  }
  if (meta.map_sha256 != now.map_sha256) {
    found.push_back({"versions.map_sha256", meta.map_sha256, now.map_sha256,
                     "the map image of " + (now.scenario_file.empty() ? std::string("the scenario") : now.scenario_file) +
                         " changed since the recording"});
  }
  return found;
}

std::string describe(const ProvenanceMismatch& mismatch) {
  const bool hash = mismatch.field.find("sha256") != std::string::npos;
  return mismatch.field + " differs: recorded '" + mismatch.recorded + "', " + (hash ? "now '" : "this build '") +
         mismatch.here + "' (" + mismatch.what + ")";
}

}  // namespace rfbsim::replay
