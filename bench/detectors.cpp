// The edge detectors side by side: vision::extract_chains_from_image with each
// [vision] detector (canny, surround, bilateral, edpf) on every test picture and on generated texture
// (tests/support/textures.hpp), from the decoded, downscaled grey image. Counters: chains found (before
// any simplification) and their total length [processed px]. What each gives a hand after the
// simplification is measured end to end by bench/scene_detectors.sh.
#include <benchmark/benchmark.h>

#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "bench_scenes.hpp"
#include "textures.hpp"
#include "vision/intake.hpp"
#include "vision/linking.hpp"
#include "vision/pipeline.hpp"

using namespace hk;

namespace {

/// A picture as the detectors see it: decoded, grey, shrunk to max_image_side_px.
struct Picture {
  std::string name;
  cv::Mat grey;
};

std::vector<Picture>& pictures() {
  static std::vector<Picture> v;
  return v;
}

void run(benchmark::State& state, const Picture* p, vision::Detector d) {
  const config::Settings s;
  vision::ExtractParams ep;
  ep.detector = d;
  ep.edges.blur_sigma_px = s.vision.blur_sigma_px;
  ep.max_image_side_px = s.vision.max_image_side_px;
  ep.surround_inhibition = s.vision.surround_inhibition;
  ep.min_chain_length_px = 2.0;
  std::size_t chains = 0;
  double length_px = 0.0;
  for (auto _ : state) {
    const vision::Extraction ex = vision::extract_chains_from_image(p->grey, ep);
    chains = ex.chains.size();
    length_px = 0.0;
    for (const vision::Chain& c : ex.chains) length_px += vision::chain_length_px(c);
    benchmark::DoNotOptimize(ex.chains.data());
  }
  state.counters["chains"] = static_cast<double>(chains);
  state.counters["length_px"] = length_px;
}

/// The generated textures of the comparison: (name, picture).
std::vector<Picture> textures() {
  return {{"texture_noise", test::noise_texture(800, 520, 1)}, {"texture_wood", test::wood_texture(800, 520, 2)}};
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 3 && std::string(argv[1]) == "--write-textures") {
    for (const Picture& t : textures()) {
      if (!cv::imwrite(std::string(argv[2]) + "/" + t.name + ".png", t.grey)) return 1;
    }
    return 0;
  }
  benchmark::Initialize(&argc, argv);
  const config::Settings s;
  vision::ImageLimits limits;
  for (const auto& path : bench::picture_paths()) {
    double px_scale = 1.0;
    pictures().push_back({path.stem().string(), vision::to_grey(vision::load_image(path.string(), limits),
                                                                s.vision.max_image_side_px, &px_scale)});
  }
  for (Picture& t : textures()) pictures().push_back(std::move(t));
  for (const Picture& p : pictures()) {
    for (const vision::Detector d :
         {vision::Detector::Canny, vision::Detector::Surround, vision::Detector::Bilateral, vision::Detector::Edpf}) {
      const std::string name = std::string("BM_Detector/") + vision::detector_name(d) + "/" + p.name;
      benchmark::RegisterBenchmark(name.c_str(), [&p, d](benchmark::State& st) {
        run(st, &p, d);
      })->Unit(benchmark::kMillisecond);
    }
  }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
}
