// Sensor effects and small image utilities (no OpenCV needed).
#include <cmath>
#include <cstdio>
#include <vector>

#include "arflex_sim/render.h"

namespace arflex {
namespace sim {
namespace {

// Standard-normal samples for the noise: 65536 precomputed values (Box-Muller over a
// splitmix64 stream) indexed by a xorshift generator, so that a 1280x1024 frame does not
// cost four million logarithms.
const std::vector<float>& NormalTable() {
  static const std::vector<float> table = [] {
    std::vector<float> t(65536);
    uint64_t state = 0x5EED5EED5EEDULL;
    auto next = [&state] {
      uint64_t z = (state += 0x9E3779B97F4A7C15ULL);
      z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
      z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
      return z ^ (z >> 31);
    };
    for (size_t i = 0; i < t.size(); i += 2) {
      const double u1 = (static_cast<double>(next() >> 11) + 0.5) * 0x1.0p-53;
      const double u2 = (static_cast<double>(next() >> 11) + 0.5) * 0x1.0p-53;
      const double r = std::sqrt(-2.0 * std::log(u1));
      t[i] = static_cast<float>(r * std::cos(2.0 * M_PI * u2));
      t[i + 1] = static_cast<float>(r * std::sin(2.0 * M_PI * u2));
    }
    return t;
  }();
  return table;
}

uint8_t Clamp8(float v) {
  if (v <= 0.0f) return 0;
  if (v >= 255.0f) return 255;
  return static_cast<uint8_t>(v + 0.5f);
}

void Blur(uint8_t* rgb, int width, int height, double sigma, std::vector<float>* work) {
  const int radius = static_cast<int>(std::ceil(3.0 * sigma));
  std::vector<float> kernel(2 * radius + 1);
  float sum = 0.0f;
  for (int i = -radius; i <= radius; ++i) {
    kernel[i + radius] = static_cast<float>(std::exp(-0.5 * i * i / (sigma * sigma)));
    sum += kernel[i + radius];
  }
  for (float& k : kernel) k /= sum;
  const size_t n = static_cast<size_t>(width) * height * 3;
  work->resize(n);
  float* tmp = work->data();
  // Horizontal pass into tmp, vertical pass back into rgb; edges clamp.
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      for (int c = 0; c < 3; ++c) {
        float acc = 0.0f;
        for (int i = -radius; i <= radius; ++i) {
          const int xx = x + i < 0 ? 0 : (x + i >= width ? width - 1 : x + i);
          acc += kernel[i + radius] * rgb[(y * width + xx) * 3 + c];
        }
        tmp[(y * width + x) * 3 + c] = acc;
      }
    }
  }
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      for (int c = 0; c < 3; ++c) {
        float acc = 0.0f;
        for (int i = -radius; i <= radius; ++i) {
          const int yy = y + i < 0 ? 0 : (y + i >= height ? height - 1 : y + i);
          acc += kernel[i + radius] * tmp[(yy * width + x) * 3 + c];
        }
        rgb[(y * width + x) * 3 + c] = Clamp8(acc);
      }
    }
  }
}

uint32_t Crc32(const uint8_t* data, size_t n, uint32_t crc = 0) {
  crc = ~crc;
  for (size_t i = 0; i < n; ++i) {
    crc ^= data[i];
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

void PutBe32(std::vector<uint8_t>* out, uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) out->push_back(static_cast<uint8_t>(v >> s));
}

void Chunk(std::vector<uint8_t>* png, const char* type, const std::vector<uint8_t>& data) {
  PutBe32(png, static_cast<uint32_t>(data.size()));
  std::vector<uint8_t> body(type, type + 4);
  body.insert(body.end(), data.begin(), data.end());
  png->insert(png->end(), body.begin(), body.end());
  PutBe32(png, Crc32(body.data(), body.size()));
}

}  // namespace

void ApplySensorEffects(uint8_t* rgb, int width, int height, SensorEffects* effects,
                        std::vector<float>* work) {
  if (effects->blur_sigma > 0.0) Blur(rgb, width, height, effects->blur_sigma, work);
  if (effects->noise_sigma > 0.0) {
    const std::vector<float>& table = NormalTable();
    const float sigma = static_cast<float>(effects->noise_sigma);
    uint64_t x = effects->seed * 0x2545F4914F6CDD1DULL + 0x9E3779B97F4A7C15ULL;
    if (x == 0) x = 1;
    const size_t n = static_cast<size_t>(width) * height * 3;
    for (size_t i = 0; i < n; ++i) {
      x ^= x << 13;  // xorshift64 (Marsaglia 2003)
      x ^= x >> 7;
      x ^= x << 17;
      rgb[i] = Clamp8(rgb[i] + sigma * table[(x >> 20) & 0xFFFF]);
    }
    effects->seed = x;  // the next frame gets fresh noise
  }
}

void RgbToGray(const uint8_t* rgb, int width, int height, uint8_t* gray) {
  const size_t n = static_cast<size_t>(width) * height;
  for (size_t i = 0; i < n; ++i) {
    const int y = 299 * rgb[3 * i] + 587 * rgb[3 * i + 1] + 114 * rgb[3 * i + 2];
    gray[i] = static_cast<uint8_t>((y + 500) / 1000);
  }
}

bool WritePng(const std::string& path, const uint8_t* pixels, int width, int height,
              int channels) {
  if (channels != 1 && channels != 3) return false;
  // Raw scanlines with filter byte 0, wrapped in stored (uncompressed) deflate blocks.
  std::vector<uint8_t> raw;
  const size_t stride = static_cast<size_t>(width) * channels;
  raw.reserve((stride + 1) * height);
  for (int y = 0; y < height; ++y) {
    raw.push_back(0);
    raw.insert(raw.end(), pixels + y * stride, pixels + (y + 1) * stride);
  }
  std::vector<uint8_t> z = {0x78, 0x01};
  size_t pos = 0;
  do {
    const size_t len = std::min<size_t>(65535, raw.size() - pos);
    z.push_back(pos + len == raw.size() ? 1 : 0);
    z.push_back(static_cast<uint8_t>(len));
    z.push_back(static_cast<uint8_t>(len >> 8));
    z.push_back(static_cast<uint8_t>(~len));
    z.push_back(static_cast<uint8_t>(~len >> 8));
    z.insert(z.end(), raw.begin() + pos, raw.begin() + pos + len);
    pos += len;
  } while (pos < raw.size());
  uint32_t a = 1, b = 0;
  for (uint8_t v : raw) {
    a = (a + v) % 65521;
    b = (b + a) % 65521;
  }
  PutBe32(&z, (b << 16) | a);
  std::vector<uint8_t> png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  std::vector<uint8_t> ihdr;
  PutBe32(&ihdr, static_cast<uint32_t>(width));
  PutBe32(&ihdr, static_cast<uint32_t>(height));
  ihdr.push_back(8);
  ihdr.push_back(channels == 3 ? 2 : 0);
  ihdr.push_back(0);
  ihdr.push_back(0);
  ihdr.push_back(0);
  Chunk(&png, "IHDR", ihdr);
  Chunk(&png, "IDAT", z);
  Chunk(&png, "IEND", {});
  FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return false;
  const bool ok = std::fwrite(png.data(), 1, png.size(), f) == png.size();
  return std::fclose(f) == 0 && ok;
}

}  // namespace sim
}  // namespace arflex
