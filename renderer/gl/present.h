#pragma once
// Frame presentation helpers for windowed code outside renderer/gl (the session runner):
// clearing the default framebuffer and waiting for the GPU, so no raw GL call lives in
// study/.
namespace lucent::gl {

// Sets the viewport to width x height and clears the bound framebuffer's colour to the
// opaque linear colour `rgb` through the final colour pass (core/display_transform.h):
// the screen's background has the codes of the stimuli's rendered background.
void clear_frame(int width, int height, const float rgb[3]);

// Blocks until the GPU has executed every command issued so far (glFinish): before a
// swap, the frame is complete; after it, the swap has happened.
void wait_for_gpu();

}  // namespace lucent::gl
