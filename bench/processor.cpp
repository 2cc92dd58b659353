#include "bench/processor.h"

#include <cpuid.h>

namespace pathlab::bench {

std::string processor() {
  unsigned eax = 0, ebx = 0, ecx = 0, edx = 0;
  if (__get_cpuid(1, &eax, &ebx, &ecx, &edx) == 0) return "unknown";
  const unsigned base_family = (eax >> 8) & 0xf;
  const unsigned family = base_family == 0xf ? base_family + ((eax >> 20) & 0xff) : base_family;
  const unsigned model =
      base_family == 0x6 || base_family == 0xf ? ((eax >> 4) & 0xf) | (((eax >> 16) & 0xf) << 4) : (eax >> 4) & 0xf;
  char brand[49] = {};
  if (__get_cpuid_max(0x80000000u, nullptr) >= 0x80000004u)
    for (unsigned leaf = 0; leaf < 3; ++leaf)
      __get_cpuid(0x80000002u + leaf, reinterpret_cast<unsigned*>(brand + 16 * leaf),
                  reinterpret_cast<unsigned*>(brand + 16 * leaf + 4), reinterpret_cast<unsigned*>(brand + 16 * leaf + 8),
                  reinterpret_cast<unsigned*>(brand + 16 * leaf + 12));
  std::string name(brand);
  name.erase(0, name.find_first_not_of(' '));
  return name + " (family " + std::to_string(family) + ", model " + std::to_string(model) + ", AVX-512 " +
         (__builtin_cpu_supports("avx512f") ? "yes" : "no") + ")";
}

}  // namespace pathlab::bench
