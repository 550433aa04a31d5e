// The Vulkan device under zink (Mesa's OpenGL on Vulkan): its name, driver, versions and
// rasterization limits, asked through the Vulkan loader zink already loaded (opened with
// dlopen, so rastercheck does not link Vulkan). Compiled to a stub that always says why
// not when the build found no Vulkan headers.
#pragma once

#include <optional>
#include <string>

#include <nlohmann/json.hpp>

namespace rc::gl {

struct VulkanDevice {
  std::string name;                  // VkPhysicalDeviceProperties::deviceName
  std::string type;                  // cpu, integrated-gpu, discrete-gpu, virtual-gpu, other
  std::string api_version;           // "1.3.230"
  std::string driver_version;        // Mesa's encoding (major.minor.patch); hex for other vendors
  std::string driver_name;           // VkPhysicalDeviceDriverProperties (Vulkan 1.2), "" before
  std::string driver_info;           // e.g. "Mesa 22.3.6 (LLVM 15.0.6)"
  int subpixel_precision_bits = -1;  // VkPhysicalDeviceLimits::subPixelPrecisionBits
  int viewport_subpixel_bits = -1;
  std::string loader;  // the real path of the Vulkan loader library
};

// zink names its device in GL_RENDERER: "zink (llvmpipe (LLVM 15.0.6, 256 bits))" gives
// "llvmpipe (LLVM 15.0.6, 256 bits)"; "" when the renderer is not zink's.
std::string zinkDeviceName(const std::string& gl_renderer);

// The physical device called `name` (the first CPU device when `name` is empty), from a
// Vulkan instance of its own. On failure returns nullopt and says why in `why`.
std::optional<VulkanDevice> queryVulkanDevice(const std::string& name, std::string& why);

// frame.json "vulkan".
nlohmann::json toJson(const VulkanDevice& device);

}  // namespace rc::gl
