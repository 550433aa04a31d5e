// The Vulkan device under zink: see vulkan_device.h.
#include "gl_backend/vulkan_device.h"

#include <fmt/format.h>

#ifdef RC_HAVE_VULKAN_HEADERS
#define VK_NO_PROTOTYPES
#include <dlfcn.h>
#include <vulkan/vulkan.h>

#include <filesystem>
#include <vector>
#endif

namespace rc::gl {

std::string zinkDeviceName(const std::string& gl_renderer) {
  constexpr std::string_view kPrefix = "zink (";
  if (gl_renderer.compare(0, kPrefix.size(), kPrefix) != 0 || gl_renderer.back() != ')') return "";
  return gl_renderer.substr(kPrefix.size(), gl_renderer.size() - kPrefix.size() - 1);
}

#ifdef RC_HAVE_VULKAN_HEADERS
namespace {

std::string versionText(std::uint32_t v) {
  return fmt::format("{}.{}.{}", VK_API_VERSION_MAJOR(v), VK_API_VERSION_MINOR(v),
                     VK_API_VERSION_PATCH(v));
}

// VK_MAKE_VERSION's packing (10/10/12 bits, no variant), what Mesa uses for driverVersion.
std::string driverVersionText(std::uint32_t v) {
  return fmt::format("{}.{}.{}", v >> 22U, (v >> 12U) & 0x3ffU, v & 0xfffU);
}

const char* typeName(VkPhysicalDeviceType type) {
  switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_CPU:
      return "cpu";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
      return "integrated-gpu";
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
      return "discrete-gpu";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
      return "virtual-gpu";
    default:
      return "other";
  }
}

// Destroys the instance on every exit path.
struct Instance {
  VkInstance handle = VK_NULL_HANDLE;
  PFN_vkDestroyInstance destroy = nullptr;
  ~Instance() {
    if (handle != VK_NULL_HANDLE && destroy != nullptr) destroy(handle, nullptr);
  }
};

}  // namespace

std::optional<VulkanDevice> queryVulkanDevice(const std::string& name, std::string& why) {
  // zink has loaded the loader already; this only takes another reference.
  void* lib = ::dlopen("libvulkan.so.1", RTLD_NOW | RTLD_LOCAL);
  if (lib == nullptr) {
    const char* e = ::dlerror();
    why = fmt::format("cannot load libvulkan.so.1: {}", e ? e : "unknown error");
    return std::nullopt;
  }
  auto get_proc =
      reinterpret_cast<PFN_vkGetInstanceProcAddr>(::dlsym(lib, "vkGetInstanceProcAddr"));
  if (get_proc == nullptr) {
    why = "libvulkan.so.1 does not export vkGetInstanceProcAddr";
    return std::nullopt;
  }
  VulkanDevice out;
  Dl_info info{};
  if (::dladdr(reinterpret_cast<void*>(get_proc), &info) != 0 && info.dli_fname != nullptr) {
    std::error_code ec;
    const std::filesystem::path real = std::filesystem::canonical(info.dli_fname, ec);
    out.loader = ec ? info.dli_fname : real.string();
  }
  auto create = reinterpret_cast<PFN_vkCreateInstance>(get_proc(nullptr, "vkCreateInstance"));
  if (create == nullptr) {
    why = "the Vulkan loader has no vkCreateInstance";
    return std::nullopt;
  }
  VkApplicationInfo app{};
  app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
  app.pApplicationName = "rastercheck";
  app.apiVersion = VK_API_VERSION_1_1;
  VkInstanceCreateInfo create_info{};
  create_info.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
  create_info.pApplicationInfo = &app;
  Instance instance;
  if (const VkResult r = create(&create_info, nullptr, &instance.handle); r != VK_SUCCESS) {
    instance.handle = VK_NULL_HANDLE;
    why = fmt::format("vkCreateInstance failed (VkResult {})", static_cast<int>(r));
    return std::nullopt;
  }
  instance.destroy =
      reinterpret_cast<PFN_vkDestroyInstance>(get_proc(instance.handle, "vkDestroyInstance"));
  auto enumerate = reinterpret_cast<PFN_vkEnumeratePhysicalDevices>(
      get_proc(instance.handle, "vkEnumeratePhysicalDevices"));
  auto properties = reinterpret_cast<PFN_vkGetPhysicalDeviceProperties>(
      get_proc(instance.handle, "vkGetPhysicalDeviceProperties"));
  auto properties2 = reinterpret_cast<PFN_vkGetPhysicalDeviceProperties2>(
      get_proc(instance.handle, "vkGetPhysicalDeviceProperties2"));
  if (instance.destroy == nullptr || enumerate == nullptr || properties == nullptr) {
    why = "the Vulkan loader lacks a Vulkan 1.0 entry point";
    return std::nullopt;
  }
  std::uint32_t count = 0;
  enumerate(instance.handle, &count, nullptr);
  std::vector<VkPhysicalDevice> devices(count);
  if (count > 0) enumerate(instance.handle, &count, devices.data());
  devices.resize(count);
  std::vector<std::string> names;
  for (VkPhysicalDevice device : devices) {
    VkPhysicalDeviceProperties p{};
    properties(device, &p);
    names.emplace_back(p.deviceName);
    const bool wanted =
        name.empty() ? p.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU : name == p.deviceName;
    if (!wanted) continue;
    out.name = p.deviceName;
    out.type = typeName(p.deviceType);
    out.api_version = versionText(p.apiVersion);
    out.subpixel_precision_bits = static_cast<int>(p.limits.subPixelPrecisionBits);
    out.viewport_subpixel_bits = static_cast<int>(p.limits.viewportSubPixelBits);
    // VkPhysicalDeviceDriverProperties is core in 1.2; older devices would not know it.
    if (properties2 != nullptr && p.apiVersion >= VK_API_VERSION_1_2) {
      VkPhysicalDeviceDriverProperties driver{};
      driver.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES;
      VkPhysicalDeviceProperties2 p2{};
      p2.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2;
      p2.pNext = &driver;
      properties2(device, &p2);
      out.driver_name = driver.driverName;
      out.driver_info = driver.driverInfo;
    }
    // Mesa's drivers pack Mesa's version the VK_MAKE_VERSION way; other vendors have
    // their own encodings, kept as the raw number.
    const bool mesa = p.vendorID == VK_VENDOR_ID_MESA || out.driver_info.rfind("Mesa", 0) == 0;
    out.driver_version =
        mesa ? driverVersionText(p.driverVersion) : fmt::format("0x{:08x}", p.driverVersion);
    return out;
  }
  std::string list;
  for (const std::string& n : names) list += (list.empty() ? "" : ", ") + n;
  why = fmt::format("no Vulkan device called '{}' (found: {})",
                    name.empty() ? "<a CPU device>" : name, list.empty() ? "none" : list);
  return std::nullopt;
}

#else

std::optional<VulkanDevice> queryVulkanDevice(const std::string& /*name*/, std::string& why) {
  why = "this build has no Vulkan headers (libvulkan-dev was not found at configure time)";
  return std::nullopt;
}

#endif

nlohmann::json toJson(const VulkanDevice& d) {
  auto text = [](const std::string& s) {
    return s.empty() ? nlohmann::json(nullptr) : nlohmann::json(s);
  };
  return {{"device", d.name},
          {"device_type", d.type},
          {"api_version", d.api_version},
          {"driver_version", d.driver_version},
          {"driver_name", text(d.driver_name)},
          {"driver_info", text(d.driver_info)},
          {"subpixel_precision_bits", d.subpixel_precision_bits},
          {"viewport_subpixel_bits", d.viewport_subpixel_bits},
          {"loader", text(d.loader)}};
}

}  // namespace rc::gl
