#pragma once
/// @file kiosk_flow.hpp
/// What a visitor walks through (issue 5, item 5), as a state machine apart from windows and devices so
/// it can be driven by scripted input in tests:
///   Attract   — waiting; the first key press or handle motion speaks the welcome and starts the tutorial;
///   Tutorial  — a square, a circle, a triangle (Next moves on); after the triangle, the first picture;
///   Picture   — Next / Previous picture, Describe, Finer / Coarser level, Volume, Help, Tutorial again,
///               Guide (the guided tour, also on the tutorial's shapes; any key stops a running tour).
/// Every key press is answered in speech at once (the speech cuts off what was being said). With no key
/// and no handle motion for `timeout_s`, the kiosk warns `warning_s` ahead, then says goodbye, restores the
/// operator's defaults and returns to Attract. Any key or motion extends the time.
///
/// USB sticks (issue 11, item 5): a stick inserted (stick_inserted) makes Next / Previous walk its documents
/// and their pages instead of the picture library. Its first page is loaded at once and announced after a
/// summary of the stick ("A USB stick with 3 documents: 2 pictures and a PDF of 12 pages. Press the Right arrow ...").
/// Documents load asynchronously (KioskEffects::show_document; the window layer reports back with
/// document_ready), so slow work never blocks; "Loading." is said when a load takes longer than
/// loading_cue_s. A page that cannot be read is reported and the picture felt before stays. Removing the
/// stick goes back to the library picture; a new session forgets the stick.
///
/// The camera (issue 16, item 3): the Capture key starts a capture (KioskEffects::start_capture) guided by voice
/// (capture_advice, each advice said as it comes, cutting off the one before); any key cancels it; when the
/// picture is taken (capture_done) the Shutter earcon has sounded and the flow says "Captured. It has N shapes."
/// and stays on it (Next and Previous go on in the library). A failure or a time-out is said. Without a camera
/// the key says so, and the help names the key only when there is a camera (KioskFlowParams::camera).
///
/// Keys (issue 12, item 6): what the kiosk says names the keys that work. Every message is said with its
/// key placeholders ({help_key}, {next_key}, …) filled from the [keys] settings (KioskFlowParams::keys, changed
/// live with set_keys()), as the catalogue's spoken form of each key ("Press the Up arrow for more detail.").

#include <array>
#include <string>
#include <vector>

#include "audio/messages.hpp"
#include "picture_notes.hpp"
#include "config/settings.hpp"

namespace hk::app {

/// Keys a blind visitor can find (mapped to physical keys in the config by the window layer).
enum class KioskKey { Help, Next, Previous, Describe, Finer, Coarser, VolumeUp, VolumeDown, Tutorial, Guide, Capture, Other };

/// States of the flow.
enum class KioskState { Attract, Tutorial, Picture };

/// The state's name for the operator's screens: "attract", "tutorial", "picture".
const char* state_name(KioskState s);

/// Tutorial shapes, in order.
enum class TutorialShape { Square = 0, Circle = 1, Triangle = 2 };

/// A document of a USB stick as the flow sees it.
struct StickEntry {
  std::string name;   ///< file name made safe for speech
  bool pdf = false;   ///< a PDF (pages) or a picture
  int pages = 1;      ///< pages offered (1 for a picture)
  std::string title;  ///< the document's own title (ListedDocument::title), spoken in place of `name`; "" when none
};

/// Where Next and Previous go.
enum class KioskSource { Library, Stick };

/// The outcome of an asynchronous document load (KioskEffects::show_document), reported by the window layer.
struct DocumentResult {
  int document = 0;          ///< as requested
  int page = 1;              ///< as requested (from 1)
  bool ok = false;           ///< the scene is on the device
  std::string description;   ///< ok: what the page holds, one sentence ("It has 3 shapes and 2 blocks of text.")
  std::string reason;        ///< !ok: why it cannot be shown, one line for speech
};

/// What the flow asks of the rest of the kiosk. The window layer implements it with the AudioSystem, the
/// servo core and the picture library; tests record the calls.
class KioskEffects {
 public:
  virtual ~KioskEffects() = default;
  /// Speak `text` now, cutting off what is being said.
  virtual void say(const std::string& text) = 0;
  /// Put a tutorial shape on the device.
  virtual void show_tutorial(TutorialShape shape) = 0;
  /// Put picture `index` (0-based) on the device. Returns its number of shapes.
  virtual int show_picture(int index) = 0;
  /// Pictures in the library (≥ 1).
  virtual int picture_count() const = 0;
  /// The title and description a person wrote for the picture shown (picture_notes.hpp); empty when none.
  virtual PictureNotes shown_notes() const { return {}; }
  /// A spoken description of what is shown (describe.hpp).
  virtual std::string describe() = 0;
  /// Level one finer (delta −1) or coarser (+1). Returns false at the limit (nothing changes).
  virtual bool change_level(int delta) = 0;
  /// Volume one step up (+1) or down (−1). Returns false at the limit.
  virtual bool change_volume(int delta) = 0;
  /// A new visitor: the operator's default settings (volume, level), speech stopped.
  virtual void new_session() = 0;
  /// Start loading page `page` (from 1) of stick document `document` (0-based) off the window thread; when
  /// done, the window layer calls KioskFlow::document_ready. A newer request supersedes an older one.
  virtual void show_document(int document, int page) = 0;
  /// Drop the stick's listing (a new visitor must not browse the last one's stick).
  virtual void forget_stick() = 0;
  /// Any key was pressed (before the flow acts on it): a guided tour that runs stops (issue 14, item 3).
  /// Default: nothing.
  virtual void key_pressed() {}
  /// The Capture key (issue 16): start a guided camera capture off the window thread; the window layer then
  /// reports with KioskFlow::capture_advice / capture_done / capture_failed. False when there is no camera
  /// (nothing starts). Default: no camera.
  virtual bool start_capture() { return false; }
  /// Stop the capture under way (a key was pressed or the session ended); no report follows. Default: nothing.
  virtual void cancel_capture() {}
  /// The Guide key (issue 14, item 3): lead the handle to the nearest shape not yet touched and round it,
  /// or, when the press stopped a running tour (key_pressed), say so. What is said is up to the
  /// implementation (the tour's end is reported later). Default: nothing.
  virtual void guide() {}
};

/// The key placeholders of the catalogue ({help_key} … {tutorial_key}, audio::kKeyPlaceholders) paired with the
/// keys of `keys`, for audio::MessageCatalog::text(). The pairs view the strings of `keys`: keep it alive while
/// they are used. For anything outside the flow that says a message naming keys (e.g. `haptic-kiosk speak`).
std::array<audio::KeyArg, audio::kKeyPlaceholders.size()> key_args(const config::KeysSettings& keys);

/// Timing of the flow. Units in names.
struct KioskFlowParams {
  double timeout_s = 120.0;  ///< no key and no motion for this long ends the session
  double warning_s = 20.0;   ///< the spoken warning comes this long before the end (at most timeout_s / 2)
  double loading_cue_s = 0.5; ///< "Loading." is said when a document takes longer than this to load
  config::KeysSettings keys{};  ///< the key of each action ([keys]), named in what is said; default: the shipped keys
  bool camera = false;          ///< a camera is there: the help names the Capture key
};

/// The state machine. Not thread-safe: call from the window thread.
class KioskFlow {
 public:
  KioskFlow(KioskEffects& effects, const audio::MessageCatalog& messages, const KioskFlowParams& params = {});

  /// A key press at time `now_s` [s] (any monotonic clock).
  void key(KioskKey k, double now_s);
  /// The handle moved noticeably (the caller decides, e.g. > 5 mm since the last call) at `now_s`.
  void handle_moved(double now_s);
  /// Time passes (call every frame): warnings, the time-out and the loading cue.
  void tick(double now_s);
  /// A USB stick was inserted and scanned: its documents (may be empty), at `now_s`. Wakes the kiosk.
  void stick_inserted(const std::vector<StickEntry>& documents, double now_s);
  /// A stick was refused (unsupported filesystem, unreadable): `reason` is spoken.
  void stick_refused(const std::string& reason, double now_s);
  /// The stick was taken out: back to the library.
  void stick_removed(double now_s);
  /// A load asked for with show_document finished (ignored unless it is the one awaited).
  void document_ready(const DocumentResult& result, double now_s);
  /// The capture under way says `advice` (one of the capture_* messages, capture.hpp advice_message). Counts as
  /// activity (the visitor is busy placing the picture). Ignored when no capture is under way.
  void capture_advice(audio::MessageId advice, double now_s);
  /// The capture under way took its picture and put it on the device with `shapes` shapes: said, and the
  /// flow is on that picture. Ignored when no capture is under way.
  void capture_done(int shapes, double now_s);
  /// The capture under way ended without a picture: the camera failed (timeout = false) or the picture never
  /// lay still long enough (timeout = true). Said; the picture felt before stays.
  void capture_failed(bool timeout, double now_s);
  /// A capture is under way.
  bool capturing() const { return capturing_; }
  /// The operator changed the keys ([keys]): from now on every message names these (the next thing said
  /// already does). Does not speak and does not touch the session.
  void set_keys(const config::KeysSettings& keys) { p_.keys = keys; }
  /// The operator changed the session's time-out ([kiosk] timeout_s, warning_s [s]): counted from the last
  /// activity, as before. A warning already given stays given.
  void set_timing(double timeout_s, double warning_s) {
    p_.timeout_s = timeout_s;
    p_.warning_s = warning_s;
  }
  /// The keys named in what is said.
  const config::KeysSettings& keys() const { return p_.keys; }
  /// The text of `id` as the flow says it: `args` filled in, and every key placeholder naming the current key.
  std::string text(audio::MessageId id, std::initializer_list<audio::MessageArg> args = {}) const;

  KioskSource source() const { return source_; }
  int document() const { return doc_; }        ///< stick document shown (0-based), −1 before the first
  int page() const { return page_; }           ///< its page (from 1)
  bool loading() const { return pending_doc_ >= 0; }  ///< a document load is awaited

  KioskState state() const { return state_; }
  TutorialShape tutorial_shape() const { return shape_; }
  int picture() const { return picture_; }
  bool warned() const { return warned_; }

 private:
  void wake(double now_s);
  void start_tutorial();
  void show(int index, const std::string& before = {});
  void say(audio::MessageId id, std::initializer_list<audio::MessageArg> args = {});
  void say_help();  // the help, and the Capture key's sentence when there is a camera
  void request(int document, int page, double now_s);
  void step_document(int delta, double now_s);
  std::string stick_summary() const;

  KioskEffects& fx_;
  const audio::MessageCatalog& msg_;
  KioskFlowParams p_;
  KioskState state_ = KioskState::Attract;
  TutorialShape shape_ = TutorialShape::Square;
  int picture_ = 0;
  double last_activity_s_ = 0;
  bool warned_ = false;
  KioskSource source_ = KioskSource::Library;
  std::vector<StickEntry> stick_;
  int doc_ = -1, page_ = 1;                 // shown
  int at_doc_ = -1, at_page_ = 1;           // where browsing stands: the last page asked for, shown or not
  int pending_doc_ = -1, pending_page_ = 1; // awaited
  double pending_since_s_ = 0;
  bool loading_said_ = false;
  std::string announce_summary_;            // the stick's summary, said before the first page's announcement
  bool capturing_ = false;                  // a camera capture is under way
};

}  // namespace hk::app
