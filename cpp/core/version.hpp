#pragma once

namespace homesh {
inline constexpr const char* kVersion = "0.1.0";
}
