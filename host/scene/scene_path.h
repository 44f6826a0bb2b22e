// scene_path.h: turning a file name written in a scene into the file it means.
#pragma once

#include <string>

namespace narval::scene_detail {

// Expands ${VAR} and ${VAR:-default} from the environment, as a shell would (the default, itself
// expanded, applies when VAR is unset or empty), so a scene can say
// "${NARVAL_DATA_DIR:-../data}/cloud.vdb". A bare $ is literal. An unset VAR without a default,
// or a malformed reference, throws "FILE: KEY: ..." (naming the scene key).
std::string expandEnvironment(const std::string& text, const std::string& file, const std::string& key);

// Expands `raw`, resolves it against the folder of `sceneFile` when relative, normalises it and
// checks that a .vdb/.vol file is there: "FILE: KEY: volume file not found: RESOLVED".
std::string resolveVolumePath(const std::string& raw, const std::string& sceneFile,
                              const std::string& key);

}  // namespace narval::scene_detail
