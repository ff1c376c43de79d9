#include "audio/speech.hpp"

#include <espeak-ng/speak_lib.h>
#include <samplerate.h>
extern "C" {
#include <flite/flite.h>
// The CMU Flite English voices this build links (Debian flite1-dev): their registration functions.
cst_voice* register_cmu_us_slt(const char* voxdir);
cst_voice* register_cmu_us_kal(const char* voxdir);
cst_voice* register_cmu_us_awb(const char* voxdir);
cst_voice* register_cmu_us_rms(const char* voxdir);
}
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <exception>
#include <functional>
#include <memory>
#include <optional>

namespace hk::audio {
namespace {

/// Receives resampled speech; returns false to stop the synthesis (the utterance was cancelled).
using Sink = std::function<bool(const float*, std::size_t)>;

/// The one lock around every espeak-ng and Flite call (and the globals below).
std::mutex& espeak_mutex() {
  static std::mutex m;
  return m;
}

/// The synthesis in progress, reached from espeak-ng's callback (guarded by espeak_mutex()).
struct Synthesis {
  SRC_STATE* src = nullptr;
  double ratio = 1.0;  // kSampleRateHz / espeak-ng's rate
  Sink sink;
  std::vector<float> in, out;
  bool stopped = false;          // the sink asked to stop, or an error: abort espeak-ng
  std::string error;             // a resampler error
  std::exception_ptr exception;  // thrown by the sink inside the C callback; rethrown after it
};
Synthesis* g_current = nullptr;
std::optional<SpeechParams> g_configured;  // what espeak-ng is set to now (nullopt: unknown)

/// Converts `n` int16 samples to float, resamples them and hands them to the sink. `last` flushes the
/// resampler's tail. Returns false to stop (sink said so, or a resampler error in s.error).
bool feed(Synthesis& s, const short* pcm, std::size_t n, bool last) {
  s.in.resize(std::max<std::size_t>(n, 1));  // never a null data_in
  for (std::size_t i = 0; i < n; ++i) s.in[i] = static_cast<float>(pcm[i]) / 32768.0f;
  s.out.resize(static_cast<std::size_t>(static_cast<double>(n) * s.ratio) + 256);
  SRC_DATA d{};
  d.src_ratio = s.ratio;
  d.end_of_input = last ? 1 : 0;
  std::size_t used = 0;
  for (;;) {
    d.data_in = s.in.data() + used;
    d.input_frames = static_cast<long>(n - used);
    d.data_out = s.out.data();
    d.output_frames = static_cast<long>(s.out.size());
    if (const int err = src_process(s.src, &d); err != 0) {
      s.error = std::string("speech: resampling failed (libsamplerate: ") + src_strerror(err) + ")";
      return false;
    }
    used += static_cast<std::size_t>(d.input_frames_used);
    const auto got = static_cast<std::size_t>(d.output_frames_gen);
    // A sinc resampler overshoots a full-scale step a little: keep the promise of [-1, 1].
    for (std::size_t i = 0; i < got; ++i) s.out[i] = std::clamp(s.out[i], -1.0f, 1.0f);
    if (got > 0 && !s.sink(s.out.data(), got)) return false;
    if (used >= n && (!last || got == 0)) return true;
    if (d.input_frames_used == 0 && got == 0) return true;  // no progress possible (guard)
  }
}

/// espeak-ng's synth callback (AUDIO_OUTPUT_SYNCHRONOUS: called on the synthesising thread, inside
/// espeak_Synth). pcm == nullptr marks the end. Returns 1 to abort the synthesis.
int on_samples(short* pcm, int n, espeak_EVENT* /*events*/) {
  Synthesis* s = g_current;
  if (s == nullptr || s->stopped) return 1;
  if (pcm == nullptr || n <= 0) return 0;
  try {
    if (!feed(*s, pcm, static_cast<std::size_t>(n), false)) s->stopped = true;
  } catch (...) {  // never let an exception cross espeak-ng's C frames
    s->exception = std::current_exception();
    s->stopped = true;
  }
  return s->stopped ? 1 : 0;
}

/// The Flite voice `name` names ("flite:slt" → CMU's slt voice), registered once per process; null for a name
/// that is not a Flite voice of this build. Caller holds espeak_mutex().
cst_voice* flite_voice_locked(std::string_view name) {
  struct Known {
    std::string_view name;
    cst_voice* (*reg)(const char*);
    cst_voice* voice;
  };
  static Known known[] = {{"flite:slt", &register_cmu_us_slt, nullptr},
                          {"flite:kal", &register_cmu_us_kal, nullptr},
                          {"flite:awb", &register_cmu_us_awb, nullptr},
                          {"flite:rms", &register_cmu_us_rms, nullptr}};
  static const bool started = [] {
    flite_init();
    return true;
  }();
  (void)started;
  for (Known& k : known) {
    if (k.name != name) continue;
    if (!k.voice) k.voice = k.reg(nullptr);
    return k.voice;
  }
  return nullptr;
}

bool is_flite(std::string_view voice) { return voice.rfind("flite:", 0) == 0; }

/// Initialises espeak-ng once per process; returns its sample rate [Hz]. Caller holds espeak_mutex().
int native_rate_locked() {
  static const int rate = [] {
    // 100 ms buffers: ~2200 samples per callback, the granularity of streaming and of stopping.
    // nullptr path: espeak-ng's default data directory (Debian: /usr/lib/x86_64-linux-gnu/espeak-ng-data).
    const int r = espeak_Initialize(AUDIO_OUTPUT_SYNCHRONOUS, 100, nullptr, espeakINITIALIZE_DONT_EXIT);
    if (r > 0) espeak_SetSynthCallback(&on_samples);
    return r;
  }();
  if (rate <= 0) throw SpeechError("speech: espeak-ng could not start (is the espeak-ng-data package installed?)");
  return rate;
}

void check_text(std::string_view text) {
  if (text.size() > kMaxSpeechTextBytes) {
    throw SpeechError("speech: text of " + std::to_string(text.size()) + " bytes is over the limit of " +
                      std::to_string(kMaxSpeechTextBytes) + " bytes");
  }
}

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v'; }

/// Where the sentence starting at `from` ends (one past its last byte): after '.', '!', '?', ';' or ':'
/// followed by white space, or at a line break; text.size() when none.
std::size_t sentence_end(std::string_view text, std::size_t from) {
  for (std::size_t i = from; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '\n') return i;
    if ((c == '.' || c == '!' || c == '?' || c == ';' || c == ':') && i + 1 < text.size() && is_space(text[i + 1]))
      return i + 1;
  }
  return text.size();
}

/// Where a run of `text` longer than `max` bytes is cut: after the last space within max bytes, else at
/// the last UTF-8 sequence boundary within them (never 0).
std::size_t word_cut(std::string_view text, std::size_t max) {
  for (std::size_t i = max; i > 0; --i)
    if (is_space(text[i])) return i;
  std::size_t i = max;
  while (i > 1 && (static_cast<unsigned char>(text[i]) & 0xC0) == 0x80) --i;  // not inside a sequence
  return i;
}

std::string_view trimmed(std::string_view t) {
  while (!t.empty() && is_space(t.front())) t.remove_prefix(1);
  while (!t.empty() && is_space(t.back())) t.remove_suffix(1);
  return t;
}

void check_params(const SpeechParams& p) {
  if (p.rate_wpm < espeakRATE_MINIMUM || p.rate_wpm > espeakRATE_MAXIMUM) {
    throw SpeechError("speech: rate_wpm " + std::to_string(p.rate_wpm) + " words/min is outside [" +
                      std::to_string(espeakRATE_MINIMUM) + ", " + std::to_string(espeakRATE_MAXIMUM) + "]");
  }
  if (p.pitch < 0 || p.pitch > 100)
    throw SpeechError("speech: pitch " + std::to_string(p.pitch) + " is outside [0, 100]");
  if (p.voice.empty() || p.voice.size() > 64 ||
      p.voice.find_first_of(std::string_view("\0\n\r", 3)) != std::string::npos) {
    throw SpeechError("speech: voice name '" + p.voice.substr(0, 64) + "' must be 1 to 64 characters on one line");
  }
}

/// Sets voice, rate and pitch (skipped when espeak-ng is already set so). Caller holds espeak_mutex().
void configure_locked(const SpeechParams& p) {
  check_params(p);
  if (is_flite(p.voice)) {  // Flite's rate is set on each utterance
    if (!flite_voice_locked(p.voice)) throw SpeechError("speech: Flite has no voice '" + p.voice + "'");
    g_configured = p;
    return;
  }
  native_rate_locked();
  if (g_configured == p) return;
  g_configured.reset();  // a refusal below leaves espeak-ng half set
  if (espeak_SetVoiceByName(p.voice.c_str()) != EE_OK)
    throw SpeechError("speech: espeak-ng has no voice '" + p.voice + "'");
  if (espeak_SetParameter(espeakRATE, p.rate_wpm, 0) != EE_OK) {
    throw SpeechError("speech: espeak-ng refused rate_wpm " + std::to_string(p.rate_wpm));
  }
  if (espeak_SetParameter(espeakPITCH, p.pitch, 0) != EE_OK) {
    throw SpeechError("speech: espeak-ng refused pitch " + std::to_string(p.pitch));
  }
  g_configured = p;
}

/// Synthesises `text` with the Flite voice of `p` into `s` (a whole piece at once: a sentence, tens of
/// milliseconds), its speaking rate set by Flite's duration_stretch (its voices speak about 165 words/min at 1).
/// Caller holds espeak_mutex() and has configured.
void synthesize_flite_locked(const std::string& text, const SpeechParams& p, Synthesis& s) {
  cst_voice* v = flite_voice_locked(p.voice);
  if (!v) throw SpeechError("speech: Flite has no voice '" + p.voice + "'");
  flite_feat_set_float(v->features, "duration_stretch", 165.0f / static_cast<float>(p.rate_wpm));
  std::unique_ptr<cst_wave, void (*)(cst_wave*)> w(flite_text_to_wave(text.c_str(), v), &delete_wave);
  if (!w || w->sample_rate <= 0) throw SpeechError("speech: Flite could not synthesise the text");
  s.ratio = static_cast<double>(kSampleRateHz) / w->sample_rate;
  if (w->num_samples > 0 && !feed(s, w->samples, static_cast<std::size_t>(w->num_samples), false)) {
    if (!s.error.empty()) throw SpeechError(s.error);
    return;  // cancelled
  }
  const short none = 0;
  feed(s, &none, 0, true);  // the resampler's tail
  if (!s.error.empty()) throw SpeechError(s.error);
}

/// Synthesises `text` (non-empty) into `sink` at kSampleRateHz. Caller holds espeak_mutex() and has
/// configured. Returns normally also when the sink stopped it.
void synthesize_locked(const std::string& text, Sink sink) {
  int err = 0;
  std::unique_ptr<SRC_STATE, SRC_STATE* (*)(SRC_STATE*)> src(src_new(SRC_SINC_FASTEST, 1, &err), &src_delete);
  if (!src)
    throw SpeechError(std::string("speech: resampler could not start (libsamplerate: ") + src_strerror(err) + ")");
  Synthesis s;
  s.src = src.get();
  s.sink = std::move(sink);
  if (g_configured && is_flite(g_configured->voice)) {
    synthesize_flite_locked(text, *g_configured, s);
    return;
  }
  s.ratio = static_cast<double>(kSampleRateHz) / native_rate_locked();
  g_current = &s;
  const espeak_ERROR r =
      espeak_Synth(text.c_str(), text.size() + 1, 0, POS_CHARACTER, 0, espeakCHARS_UTF8, nullptr, nullptr);
  g_current = nullptr;
  if (s.exception) std::rethrow_exception(s.exception);
  if (!s.error.empty()) throw SpeechError(s.error);
  if (s.stopped) return;  // cancelled
  if (r != EE_OK)
    throw SpeechError("speech: espeak-ng could not synthesise the text (espeak_Synth error " + std::to_string(r) + ")");
  const short none = 0;
  feed(s, &none, 0, true);  // the resampler's tail
  if (!s.error.empty()) throw SpeechError(s.error);
}

std::int64_t steady_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

}  // namespace

std::vector<std::string> speech_pieces(std::string_view text, std::size_t piece_bytes) {
  const std::size_t max = std::clamp<std::size_t>(piece_bytes, 16, kMaxSpeechPieceBytes);
  std::vector<std::string> pieces;
  std::size_t at = 0;
  while (at < text.size()) {
    const std::size_t end = sentence_end(text, at);
    std::string_view sentence = trimmed(text.substr(at, end - at));
    at = end + 1;
    while (sentence.size() > max) {
      const std::size_t cut = word_cut(sentence, max);
      const std::string_view head = trimmed(sentence.substr(0, cut));
      if (!head.empty()) pieces.emplace_back(head);
      sentence = trimmed(sentence.substr(cut));
    }
    if (!sentence.empty()) pieces.emplace_back(sentence);
  }
  return pieces;
}

std::vector<float> synthesize_speech(std::string_view text, const SpeechParams& params) {
  check_text(text);
  std::lock_guard<std::mutex> lock(espeak_mutex());
  configure_locked(params);
  std::vector<float> out;
  for (const std::string& piece : speech_pieces(text)) {
    synthesize_locked(piece, [&](const float* x, std::size_t n) {
      out.insert(out.end(), x, x + n);
      return true;
    });
  }
  return out;
}

Speaker::Speaker(SpeechStream& stream, const SpeechParams& params) : stream_(stream), params_(params) {
  {
    std::lock_guard<std::mutex> lock(espeak_mutex());
    configure_locked(params_);  // refuse a bad voice now, not later in the worker
  }
  worker_ = std::thread([this] { run(); });
}

Speaker::~Speaker() {
  {
    std::lock_guard<std::mutex> lock(m_);
    stop_ = true;
    has_job_ = false;
    stream_.cancel();  // the worker's sink sees it and aborts espeak-ng
  }
  cv_.notify_all();
  worker_.join();
}

void Speaker::submit(std::string text, bool keep, bool again, std::size_t switch_from, const SpeechParams* switch_to,
                     std::size_t switch_until) {
  // Under m_, so two concurrent say() calls queue in the order of their generations.
  job_generation_ = stream_.cancel();
  stream_.set_paused(false);
  has_job_ = !text.empty();
  log_.emplace_back(steady_ns(), text);
  while (log_.size() > kLogEntries) log_.pop_front();
  if (!text.empty()) {
    job_params_ = again ? last_params_ : params_;
    job_switch_from_ = again ? last_switch_from_ : switch_to ? switch_from : SIZE_MAX;
    job_switch_until_ = again ? last_switch_until_ : switch_to ? switch_until : SIZE_MAX;
    job_switch_params_ = again ? last_switch_params_ : switch_to ? *switch_to : params_;
    if (keep) {
      last_ = text;
      last_params_ = job_params_;
      last_switch_from_ = job_switch_from_;
      last_switch_until_ = job_switch_until_;
      last_switch_params_ = job_switch_params_;
    }
    job_text_ = std::move(text);
  }
}

void Speaker::say(std::string text, bool keep) {
  if (text.size() > kMaxSpeechTextBytes) {
    // Cut where a piece ends, so no word is cut in two; what is left out is said in the log.
    const std::size_t cut = word_cut(text, kMaxSpeechTextBytes);
    spdlog::warn("speech: a text of {} bytes is over the limit of {} bytes; the first {} bytes are spoken", text.size(),
                 kMaxSpeechTextBytes, cut);
    text.resize(cut);
  }
  {
    std::lock_guard<std::mutex> lock(m_);
    submit(std::move(text), keep, false);
  }
  cv_.notify_all();
}

void Speaker::say_switching(std::string text, bool keep, std::size_t from_piece, const std::string& voice,
                            std::size_t until_piece) {
  SpeechParams other;
  {
    std::lock_guard<std::mutex> lock(m_);
    other = params_;
  }
  other.voice = voice;
  {
    std::lock_guard<std::mutex> lock(espeak_mutex());
    configure_locked(other);  // refuses a voice the synthesisers do not have, before anything is cut off
  }
  if (text.size() > kMaxSpeechTextBytes) text.resize(word_cut(text, kMaxSpeechTextBytes));
  {
    std::lock_guard<std::mutex> lock(m_);
    submit(std::move(text), keep, false, from_piece, &other, until_piece);
  }
  cv_.notify_all();
}

void Speaker::repeat() {
  {
    std::lock_guard<std::mutex> lock(m_);
    if (last_.empty()) return;
    submit(last_, true, true);
  }
  cv_.notify_all();
}

void Speaker::cancel() {
  std::lock_guard<std::mutex> lock(m_);
  has_job_ = false;
  stream_.cancel();
  stream_.set_paused(false);
}

void Speaker::forget() {
  cancel();
  std::lock_guard<std::mutex> lock(m_);
  last_.clear();
}

bool Speaker::pause() {
  std::lock_guard<std::mutex> lock(m_);
  if (stream_.paused() || !(working_ || has_job_ || stream_.speaking())) return false;
  stream_.set_paused(true);
  return true;
}

bool Speaker::resume() {
  std::lock_guard<std::mutex> lock(m_);
  if (!stream_.paused()) return false;
  stream_.set_paused(false);
  return true;
}

bool Speaker::paused() const { return stream_.paused(); }

bool Speaker::busy() const {
  std::lock_guard<std::mutex> lock(m_);
  if (stream_.paused()) return false;
  if (working_ || has_job_ || stream_.speaking()) return true;
  return handed_ && handed_generation_ == stream_.generation() &&
         steady_ns() - handed_at_ns_ < static_cast<std::int64_t>(kHandOverGrace * 1e9);
}

int Speaker::piece_heard() const {
  std::lock_guard<std::mutex> lock(m_);
  const std::uint32_t gen = stream_.generation();
  if (gen != job_generation_) return -1;  // cancelled, with nothing newer asked for
  if (starts_generation_ != gen || piece_starts_.empty()) return has_job_ || working_ ? 0 : -1;
  const SpeechStream::Heard heard = stream_.heard();
  if (heard.generation_low != (gen & SpeechStream::kHeardGenerationMask)) return 0;  // not reached the mixer yet
  if (!working_ && heard.samples >= utterance_samples_) return -1;                   // played to its end
  const auto after = std::upper_bound(piece_starts_.begin(), piece_starts_.end(), heard.samples);
  return std::max(0, static_cast<int>(after - piece_starts_.begin()) - 1);
}

bool Speaker::wait_idle(double timeout_s) {
  std::unique_lock<std::mutex> lock(m_);
  return cv_.wait_for(lock, std::chrono::duration<double>(std::max(timeout_s, 0.0)),
                      [this] { return !working_ && !has_job_; });
}

std::string Speaker::last_text() const {
  std::lock_guard<std::mutex> lock(m_);
  return last_;
}

std::vector<std::pair<std::int64_t, std::string>> Speaker::log() const {
  std::lock_guard<std::mutex> lock(m_);
  return {log_.begin(), log_.end()};
}

std::vector<std::string> Speaker::pieces_spoken() const {
  std::lock_guard<std::mutex> lock(m_);
  return {pieces_.begin(), pieces_.end()};
}

void Speaker::set_voice(const std::string& voice) {
  SpeechParams p;
  {
    std::lock_guard<std::mutex> lock(m_);
    p = params_;
  }
  p.voice = voice;
  {
    std::lock_guard<std::mutex> lock(espeak_mutex());
    configure_locked(p);  // refuses a voice espeak-ng does not have
  }
  std::lock_guard<std::mutex> lock(m_);
  params_ = p;
}

std::string Speaker::voice() const {
  std::lock_guard<std::mutex> lock(m_);
  return params_.voice;
}

bool Speaker::speak_piece(const std::string& piece, const SpeechParams& params, std::uint32_t gen,
                          std::uint64_t* pushed) {
  const auto retry = std::chrono::duration<double>(kFullRingRetry);
  // Synthesised whole under the synthesiser's lock (a piece is a sentence: tens of milliseconds), then handed
  // to the mixer outside it. Waiting for room in the mixer's ring takes as long as the piece plays; holding
  // the lock meanwhile would block every other caller of espeak-ng (synthesize_speech: the window thread
  // timing the Guide key's announcement) for seconds.
  std::vector<float> samples;
  {
    std::lock_guard<std::mutex> lock(espeak_mutex());
    configure_locked(params);
    synthesize_locked(piece, [&](const float* x, std::size_t n) {
      samples.insert(samples.end(), x, x + n);
      return stream_.generation() == gen;  // cancelled: abort espeak-ng now
    });
  }
  const float* x = samples.data();
  std::size_t n = samples.size();
  while (n > 0 && stream_.generation() == gen) {
    // Hand the samples to the mixer; when its ring is full, wait for the callback to make room.
    std::size_t taken = 0;
    const bool ok = stream_.push(gen, x, n, &taken);
    *pushed += taken;
    x += taken;
    n -= taken;
    if (ok) break;
    std::this_thread::sleep_for(retry);
  }
  if (stream_.generation() != gen) return false;
  spdlog::debug("speech: piece: {}", piece);
  std::lock_guard<std::mutex> lock(m_);
  pieces_.push_back(piece);
  while (pieces_.size() > kLogEntries) pieces_.pop_front();
  return true;
}

void Speaker::run() {
  const auto retry = std::chrono::duration<double>(kFullRingRetry);
  for (;;) {
    std::string text;
    SpeechParams params, switch_params;
    std::size_t switch_from = SIZE_MAX, switch_until = SIZE_MAX;
    std::uint32_t gen = 0;
    {
      std::unique_lock<std::mutex> lock(m_);
      cv_.wait(lock, [this] { return stop_ || has_job_; });
      if (stop_) return;
      text = std::move(job_text_);
      params = job_params_;
      switch_from = job_switch_from_;
      switch_until = job_switch_until_;
      switch_params = job_switch_params_;
      gen = job_generation_;
      has_job_ = false;
      working_ = true;
    }
    bool finished = false;
    if (gen == stream_.generation()) {
      try {
        bool whole = true;
        std::uint64_t pushed = 0;  // samples of this utterance handed to the stream
        const std::vector<std::string> pieces = speech_pieces(text);
        for (std::size_t k = 0; k < pieces.size(); ++k) {
          const std::string& piece = pieces[k];
          {
            std::lock_guard<std::mutex> lock(m_);
            if (starts_generation_ != gen) {
              starts_generation_ = gen;
              piece_starts_.clear();
              utterance_samples_ = UINT64_MAX;  // not known before the last piece is handed over
            }
            piece_starts_.push_back(pushed);
          }
          if (!speak_piece(piece, k >= switch_from && k < switch_until ? switch_params : params, gen, &pushed)) {
            whole = false;
            break;
          }
        }
        {
          std::lock_guard<std::mutex> lock(m_);
          if (starts_generation_ == gen) utterance_samples_ = pushed;
        }
        while (whole && stream_.generation() == gen) {
          if (stream_.finish(gen)) {
            finished = true;
            break;
          }
          std::this_thread::sleep_for(retry);
        }
      } catch (const std::exception& e) {
        // Voice and parameters were checked at construction; this is rare (out of memory, espeak-ng error).
        spdlog::warn("speech: could not say '{}': {}", text.substr(0, 60), e.what());
      }
    }
    {
      std::lock_guard<std::mutex> lock(m_);
      working_ = false;
      if (finished) {
        handed_ = true;
        handed_generation_ = gen;
        handed_at_ns_ = steady_ns();
      }
    }
    cv_.notify_all();
  }
}

}  // namespace hk::audio
