// viewer_input.h: one input of the viewer, whether it came from the window (mouse, keys) or from a
// recorded script (--script), so both drive the same controls; and the script's parser.
#pragma once

#include <string>
#include <vector>

#include <glm/vec3.hpp>

namespace narval {

struct ViewerInput {
  enum class Kind {
    Key,     // `key`: 1 2 3 (algorithm), [ ] (quality), P (snapshot), R (reset), H (help), F (frame)
    Orbit,   // a drag with the left button: `dx`, `dy` window pixels
    Pan,     // a drag with the right (or middle) button: `dx`, `dy` window pixels
    Zoom,    // mouse wheel: `dy` clicks (positive: closer)
    Fly,     // W A S D Q E held: `axes` (right, up, forward) for `seconds`
    Frames,  // scripts only: render `frames` frames with no input
  };
  Kind kind = Kind::Frames;
  char key = 0;
  float dx = 0, dy = 0;
  glm::vec3 axes{0, 0, 0};
  float seconds = 0;
  int frames = 0;
};

// The keys the viewer acts on (upper case for letters).
bool isViewerKey(char key);

// The (right, up, forward) direction of the flying keys held: W forward, S back, A left, D right,
// E up, Q down; `keys` holds their letters (either case). Returns false for any other letter.
bool flyAxes(const std::string& keys, glm::vec3* axes);

// Reads a script: one input per line, '#' starts a comment, blank lines are skipped.
//   key K                 K one of 1 2 3 [ ] P R H F
//   drag left DX DY       orbit (pixels); drag right DX DY: pan
//   scroll DY             wheel clicks, positive zooms in
//   hold KEYS SECONDS     flying keys (W A S D Q E, several at once) held for SECONDS of viewer time
//   frames N              render N frames
// Throws InputError "FILE:LINE: what is wrong" for a line it cannot read, or "FILE: cannot open".
std::vector<ViewerInput> readViewerScript(const std::string& path);
// The same from text; `name` stands for the file in messages.
std::vector<ViewerInput> parseViewerScript(const std::string& text, const std::string& name);

}  // namespace narval
