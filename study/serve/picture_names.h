#pragma once
// The names and bytes of the pictures a page is given (issue 44, item 4). A picture's
// URL must not say which stimulus it is: a staircase's comparison was readable from
// "/images/<standard>@<knob>=<value>.png", and an odd-one-out showed the standard's URL
// twice. So every slot of every trial gets a fresh opaque name, and the bytes served
// under it differ from every other serving of the same picture, so that neither a name
// nor a hash of the file tells a script which picture is which.
//
// A name is "/images/<40 hex digits>.png": 8 bytes of nonce, the picture's index in the
// study's sorted list of pictures encrypted under the nonce (4 bytes), and 8 bytes of
// MAC, all keyed by the study's session key. Any instance holding the key and the same
// protocol decodes it (nothing is kept per name); a name of another key or another list
// of pictures, or an altered one, is unknown (404). The nonce is an HMAC of the trial's
// UUID, the slot and the picture, so names never repeat across trials or slots, and a
// page asking again for the same trial is given the same names (and the same bytes).
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace lucent::study {

// A decoded name: which picture, and the seed of its serving's noise.
struct NamedPicture {
    std::string id;
    uint64_t noise_seed = 0;
};

class PictureNames {
public:
    // `ids`: every picture the study may show (any order; duplicates are one picture).
    PictureNames(std::string_view secret, std::vector<std::string> ids);

    // The URL of picture `id` in slot `slot` of trial `trial_uuid`. std::out_of_range
    // for an id not in the list.
    std::string url(std::string_view trial_uuid, size_t slot,
                    const std::string& id) const;
    // The picture a raw request target names ("/images/<name>.png", an optional query
    // ignored); nullopt for anything else.
    std::optional<NamedPicture> picture(std::string_view target) const;

private:
    std::string key_;  // raw bytes, derived from the secret and the list
    std::vector<std::string> ids_;
};

// The noise one serving adds: each colour channel strictly between 0 and 255 moves by
// -1, 0 or +1 (equally likely, from `seed` and the pixel), so the change is at most one
// step of 255 and zero on average; black, white and alpha are left as they are, so a
// background, a clipped highlight and the mask stay as rendered. `rgba`: 8-bit RGBA
// pixels. Returns how many channel values changed.
size_t add_serving_noise(std::vector<uint8_t>& rgba, uint64_t seed);

}  // namespace lucent::study
