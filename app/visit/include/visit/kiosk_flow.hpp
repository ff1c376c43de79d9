#pragma once
/// @file kiosk_flow.hpp
/// What a visitor walks through, as a state machine apart from windows and devices so it can be driven by
/// scripted input in tests:
///   Attract   — waiting; a short spoken invitation every attract_every_s (not in quiet hours); the first key
///               press or handle motion speaks a short welcome (≤ 8 s) and puts the tutorial's square on the
///               device;
///   Tutorial  — a square, a circle, a triangle (Next moves on); after the triangle, the first picture. It
///               teaches the keys a visitor needs: the welcome names the key that moves on; touching the
///               square, that a wall can be pushed through; the circle, Where (whose answer on a practice
///               shape says what far and near mean); the triangle, Guide; the first picture, Describe and
///               Repeat. Finer and Coarser on a practice shape say why they do nothing there;
///   Picture   — Next / Previous picture, Describe, Where ("what is here"), Finer / Coarser level, Volume,
///               Repeat, Pause, Help, Tutorial again, Guide (the guided tour), Capture, Finish.
///
/// The visitor is in charge (ADA §707, EN 301 549 §5, the EZ Access conventions):
/// - every key press is answered in speech at once, cutting off what was being said, but Volume, which never
///   cuts speech (while something is said the speech itself gets louder or quieter: that is the answer);
/// - Repeat says the last thing said again from its start (acknowledgements such as "Louder." are passed
///   over); Pause holds the speech where it is and, pressed again, goes on;
/// - Help comes in two layers: one sentence for where the visitor is and the two most useful keys, then, on
///   the same key again, every key; a key that does nothing says its own name and that it does nothing;
///   holding Help while pressing a key names that key and what it does, without doing it (learning mode);
/// - no time pressure: speech in progress (not paused), sliding along a shape, keys and handle motion all
///   count as activity, so the time-out never cuts a text being read; with none of them for timeout_s the
///   kiosk warns warning_s ahead (naming how to get more time: any key, and what will be lost), warns again
///   kRewarn_s later, then says goodbye, restores the operator's defaults and returns to Attract; Finish does
///   the same, once pressed twice within kFinishConfirm_s (the first press only asks: one press by accident
///   loses nothing);
/// - nothing a visitor does ends the kiosk: each key press, handle motion, time step, stick and capture event
///   runs under one guard that, on an exception, restores the flow's state as it was before, logs the
///   failure and says one short sorry line.
///
/// USB sticks: a stick inserted (stick_inserted) makes Next / Previous walk its documents and their pages
/// instead of the picture library. Its first page is loaded at once and announced after a summary of the
/// stick ("A USB stick with 3 documents: 2 pictures and a PDF of 12 pages. Press the Right arrow ...").
/// Documents load asynchronously (StickEffects::show_document; the window layer reports back with
/// document_ready), so slow work never blocks; "Loading." is said when a load takes longer than
/// loading_cue_s. A page that cannot be read is reported and the picture felt before stays. Library pictures
/// that are not at hand are built the same way (show_picture answers kPicturePending; picture_ready follows),
/// with the same "Loading." cue and the picture felt before kept until the new one is on the device. Removing the
/// stick goes back to the library picture; a new session forgets the stick.
///
/// The camera: the Capture key starts a capture (CameraEffects::start_capture) guided by voice (capture_advice,
/// each advice said as it comes, cutting off the one before); any key cancels it; when the picture is taken
/// (capture_done) the Shutter earcon has sounded and the flow says "Captured. It has N shapes." and stays on it
/// (Next and Previous go on in the library). A failure or a time-out is said. Without a camera the key says so,
/// and the help names the key only when there is a camera (KioskFlowParams::camera).
///
/// Keys: what the kiosk says names the keys that work. Every message is said with its key placeholders
/// ({help_key}, {next_key}, …) filled from the [keys] settings (KioskFlowParams::keys, changed live with
/// set_keys()), as the catalogue's spoken form of each key ("Press the Up arrow for more detail.").

#include <array>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "audio/messages.hpp"
#include "config/settings.hpp"
#include "formats/picture_notes.hpp"
#include "pictures/picture_library.hpp"
#include "visit/kiosk_effects.hpp"
#include "visit/read_aloud.hpp"

namespace hk::app {

/// Keys a blind visitor can find (mapped to physical keys in the config by the window layer), in the order of
/// config::key_actions (Help .. Finish); Other is any key that is none of them.
enum class KioskKey {
  Help,
  Next,
  Previous,
  Describe,
  Finer,
  Coarser,
  VolumeUp,
  VolumeDown,
  Tutorial,
  Guide,
  Capture,
  Repeat,
  Pause,
  Where,
  Finish,
  NextSentence,
  PreviousSentence,
  NextParagraph,
  PreviousParagraph,
  Language,
  Copy,
  Other
};

/// States of the flow.
enum class KioskState { Attract, Tutorial, Picture };

/// The state's name for the operator's screens: "attract", "tutorial", "picture".
const char* state_name(KioskState s);

/// A document of a USB stick as the flow sees it.
struct StickEntry {
  std::string name;       ///< file name made safe for speech
  bool pdf = false;       ///< a PDF (pages) or a picture
  int pages = 1;          ///< pages offered (1 for a picture)
  std::string title;      ///< the document's own title (ListedDocument::title), spoken in place of `name`; "" when none
  int pages_in_file = 0;  ///< pages the document has (more than `pages` when capped); 0: the same as `pages`
};

/// A document's name as it is spoken: a file name without its extension, underscores and dashes read as
/// spaces, and at most kSpokenNameBytes bytes (cut at a word, UTF-8 whole) so that a 254-byte name is not
/// read out in full. A title is only cut.
std::string spoken_name(const std::string& name, bool file_name);
inline constexpr std::size_t kSpokenNameBytes = 60;

/// Where Next and Previous go.
enum class KioskSource { Library, Stick };

/// The outcome of an asynchronous document load (StickEffects::show_document), reported by the window layer.
struct DocumentResult {
  int document = 0;         ///< as requested
  int page = 1;             ///< as requested (from 1)
  bool ok = false;          ///< the scene is on the device
  std::string description;  ///< ok: what the page holds, one sentence ("It has 3 shapes and 2 blocks of text.")
  std::string reason;  ///< !ok: why it cannot be shown, one line for the log and the operator (the visitor hears that
                       ///< it cannot be read)
};

/// The key placeholders of the catalogue ({help_key} … {tutorial_key}, audio::kKeyPlaceholders) paired with the
/// keys of `keys`, for audio::MessageCatalog::text(). The pairs view the strings of `keys`: keep it alive while
/// they are used. For anything outside the flow that says a message naming keys (e.g. `haptic-kiosk speak`).
std::array<audio::KeyArg, audio::kKeyPlaceholders.size()> key_args(const config::KeysSettings& keys);
/// Not for a temporary: the pairs would view strings already gone.
std::array<audio::KeyArg, audio::kKeyPlaceholders.size()> key_args(const config::KeysSettings&& keys) = delete;

/// Timing of the flow. Units in names.
struct KioskFlowParams {
  double timeout_s = 120.0;       ///< no activity (key, motion, contact, speech heard) for this long ends the session
  double warning_s = 20.0;        ///< the spoken warning comes this long before the end (at most timeout_s / 2)
  double loading_cue_s = 0.5;     ///< "Loading." is said when a document takes longer than this to load
  double attract_every_s = 30.0;  ///< the spoken invitation in Attract comes this often (0: never)
  config::KeysSettings keys{};    ///< the key of each action ([keys]), named in what is said; default: the shipped keys
  bool camera = false;            ///< a camera is there: the help names the Capture key
  bool copies = false;            ///< copies are offered: the help names the Copy key
  int copy_per_visit = 1;         ///< copies a visitor may have ([copy] per_visit)
};

/// The voice's rate [words per minute] (espeak-ng's default, the kiosk's [audio] default).
inline constexpr double kWordsPerMinute = 165.0;
/// How long `text` takes to say at kWordsPerMinute [s]: its words (runs of non-space bytes) counted, not
/// synthesised, so a text of hours costs a pass over its bytes.
double spoken_seconds(std::string_view text);

/// The flow's parameters from the settings ([kiosk] timeout_s, warning_s, attract_every_s; [keys]); `camera`:
/// whether there is a camera to capture from.
KioskFlowParams flow_params_from(const config::Settings& s, bool camera);

/// Where the visit stands (KioskFlow::view), for the window, the operator's panel, the runtime and tests. A
/// snapshot: `stick_documents` views the flow's list and holds until the flow is next called.
struct FlowView {
  KioskState state = KioskState::Attract;
  TutorialShape tutorial_shape = TutorialShape::Square;  ///< the practice shape shown (Tutorial)
  int picture = 0;                                       ///< the library picture shown or last shown (0-based)
  KioskSource source = KioskSource::Library;             ///< where Next and Previous go
  int document = -1;                                     ///< stick document shown (0-based), −1 before the first
  int page = 1;                                          ///< its page (from 1)
  std::span<const StickEntry> stick_documents;  ///< the stick's documents as the flow lists them (none without one)
  bool loading = false;                         ///< a stick page is awaited
  bool picture_pending = false;                 ///< a library picture is awaited (asked for, not yet on the device)
  bool capturing = false;                       ///< a capture is under way
  bool warned = false;                          ///< the time-out warning was said
  bool in_help = false;  ///< the visitor is stepping through the help's groups (Next and Previous move in it)
  /// Whether reading a page's text is what is being heard: the last text said is the reading and no other
  /// text has been said since; `reading_place` is where it stands (the sentence heard last).
  bool reading = false;
  ReadingPlace reading_place;
  int failures = 0;  ///< visitor actions that failed and were answered with the sorry line (logged), since the start
  int pending_document = -1, pending_page = 1;  ///< the stick page awaited (loading)

  /// Whether page `page` of stick document `document` is the load awaited (else a result for it is superseded).
  bool awaits_document(int document_index, int page_number) const {
    return source == KioskSource::Stick && pending_document == document_index && pending_page == page_number;
  }
};

/// The state machine. Not thread-safe: call from the window thread.
class KioskFlow {
 public:
  /// Finish ends the visit only when pressed again within this long of the first press [s].
  static constexpr double kFinishConfirm_s = 5.0;
  /// The Copy key's second press must come within this long of the first [s].
  static constexpr double kCopyConfirm_s = 10.0;
  /// The time-out warning is said again this long after the first, when time is left [s].
  static constexpr double kRewarn_s = 10.0;
  /// Every key's help is said this many sentences at a time (Next and Previous step through it).
  static constexpr std::size_t kHelpSentencesPerGroup = 2;
  /// Describe says how long a text is before one that takes longer than this to say [s].
  static constexpr double kLongText_s = 30.0;

  KioskFlow(KioskEffects effects, const audio::MessageCatalog& messages, const KioskFlowParams& params = {});

  /// A key press at time `now_s` [s] (any monotonic clock). `key_name`: the settings' name of the key pressed
  /// ("Q", "F5"; config/keys.hpp), spoken when `k` is Other (and when learning); empty when unknown.
  void key(KioskKey k, double now_s, std::string_view key_name = {});
  /// The Help key is held down (true) or let go (false). While held, a key press names the key and what it
  /// does without doing it (learning mode).
  void help_held(bool held) { learning_ = held; }
  /// The handle moved noticeably (the caller decides, e.g. > 5 mm since the last call) at `now_s`.
  void handle_moved(double now_s);
  /// The handle slides along a shape at `now_s` (the visitor is feeling it; the caller reports contact with
  /// motion, not a handle resting against a wall): activity, but it does not wake the kiosk from Attract.
  void touching(double now_s);
  /// Time passes (call every frame): the invitation, speech heard as activity, warnings, the time-out and the
  /// loading cue.
  void tick(double now_s);
  /// A USB stick was inserted and scanned: its documents (may be empty), at `now_s`. Wakes the kiosk.
  /// `unreadable`: pictures and PDFs on it that cannot be read, said in one line after what it holds ("2 files
  /// cannot be read."; which and why are in the log and the operator's panel).
  void stick_inserted(const std::vector<StickEntry>& documents, double now_s, int unreadable = 0);
  /// A stick was refused (unsupported filesystem, unreadable): `reason` is spoken.
  void stick_refused(const std::string& reason, double now_s);
  /// The stick was taken out: back to the library.
  void stick_removed(double now_s);
  /// A load asked for with show_document finished (ignored unless it is the one awaited).
  void document_ready(const DocumentResult& result, double now_s);
  /// Library picture `index`, asked for with show_picture (which answered kPicturePending), is on the device
  /// with `shapes` shapes: announced as show_picture's answer would have been. Ignored unless it is the one awaited.
  void picture_ready(int index, int shapes, double now_s);
  /// Library picture `index` could not be built (`reason`, one line, logged): that it cannot be read is said, and
  /// the picture felt before stays.
  /// Next and Previous go on from `index`. Ignored unless it is the one awaited.
  void picture_failed(int index, const std::string& reason, double now_s);
  /// The capture under way says `advice` (one of the capture_* messages, capture.hpp advice_message). Counts as
  /// activity (the visitor is busy placing the picture). Ignored when no capture is under way.
  void capture_advice(audio::MessageId advice, double now_s);
  /// The capture under way took its picture and put it on the device with `shapes` shapes: said, and the
  /// flow is on that picture. Ignored when no capture is under way.
  void capture_done(int shapes, double now_s);
  /// The capture under way ended without a picture: the camera failed (timeout = false) or the picture never
  /// lay still long enough (timeout = true). Said; the picture felt before stays.
  void capture_failed(bool timeout, double now_s);
  /// The copy asked for is finished: one sentence a route, printed first: printed, staff's line ([copy]
  /// printed_line, else the catalogue's) or the sorry line; saved, the folder it is in and "You can take your stick
  /// now", or why not (full, write-protected, not FAT or exFAT, no stick, the sorry line). A copy that reached
  /// neither does not count against the visit.
  void copy_finished(const CopyReport& report, double now_s);
  /// The operator changed the keys ([keys]): from now on every message names these (the next thing said
  /// already does). Does not speak and does not touch the session.
  void set_keys(const config::KeysSettings& keys) { p_.keys = keys; }
  /// The operator changed [copy]: whether copies are offered (the help names the Copy key) and how many a visitor
  /// may have, from the next press.
  void set_copies(bool offered, int per_visit) {
    p_.copies = offered;
    p_.copy_per_visit = per_visit;
  }
  /// The operator changed the session's timing ([kiosk] timeout_s, warning_s, attract_every_s [s]): counted
  /// from the last activity, as before. A warning already given stays given.
  void set_timing(double timeout_s, double warning_s, double attract_every_s);
  /// The keys named in what is said.
  const config::KeysSettings& keys() const { return p_.keys; }
  /// The text of `id` as the flow says it: `args` filled in, and every key placeholder naming the current key.
  std::string text(audio::MessageId id, std::initializer_list<audio::MessageArg> args = {}) const;
  /// A counted message in the plural form for `count` (audio::MessageCatalog::text with a count).
  std::string counted(audio::MessageId id, long count, std::initializer_list<audio::MessageArg> args = {}) const;

  /// Where the visit stands.
  FlowView view() const;

 private:
  /// Everything the flow knows of the visit, one value, so that a failed action can be undone whole.
  struct Visit {
    KioskState state = KioskState::Attract;
    TutorialShape shape = TutorialShape::Square;
    int picture = 0;
    double last_activity_s = 0;
    double started_s = -1;         // when the visitor woke the kiosk; −1 in attract before any visit
    double next_invitation_s = 0;  // Attract: when the next spoken invitation is due
    int invitation_language = -1;  // Attract: the language of the last invitation, −1 before the first
    std::string reading_language;  // the text being read is in this language, not the visitor's ("" theirs)
    bool warned = false;
    double warned_at_s = 0;      // when the first time-out warning was said
    bool rewarned = false;       // the second warning was said
    double finish_asked_s = -1;  // Finish pressed once at this time (asks for a second press); −1: not asked
    double copy_asked_s = -1;    // Copy pressed once at this time (asks for a second press); −1: not asked
    int copies_made = 0;         // copies started in this visit
    int help_layer = 0;          // 1 right after the first layer of help: Help again gives every key
    int help_group = -1;         // stepping through every key: the group said last (Next / Previous move); −1: not
    KioskSource source = KioskSource::Library;
    std::vector<StickEntry> stick;
    int doc = -1, page = 1;                  // shown
    int at_doc = -1, at_page = 1;            // where browsing stands: the last page asked for, shown or not
    int pending_doc = -1, pending_page = 1;  // awaited
    int pending_picture = -1;                // a library picture awaited
    std::string pending_before;              // said before its announcement ("Tutorial done.")
    double pending_since_s = 0;
    bool loading_said = false;
    std::string announce_summary;     // the stick's summary, said before the first page's announcement
    std::string announce_unreadable;  // how many of its files cannot be read, said after the summary
    bool capturing = false;           // a camera capture is under way
    bool captured = false;            // the picture shown is the visitor's own capture
    bool felt = false;                // a shape, picture or page has been put under the hand in this visit
    bool read_aloud_said = false;     // the visitor was told that their document is heard by people nearby
    bool push_taught = false;         // the tutorial said that a wall can be pushed through
    ReadAloud reading;                // the page's text being read, and where the visitor is in it
    bool reading_on = false;          // the reading was said, as the text kept numbered reading_kept
    std::uint64_t reading_kept = 0;
    bool reading_complete = true;          // the text being read is the page's whole text (else more blocks may come)
    bool reading_reads_on = false;         // started on a page still being read: each paragraph heard, the next follows
    bool reading_waits = false;            // the visitor asked to hear a text of which no block has been read yet,
    std::uint64_t reading_waits_kept = 0;  // when the text kept numbered this was said (anything said since: not)
  };

  void guarded(const char* what,
               const std::function<void()>& action);  // runs action; on an exception: undo, log, sorry
  void act_on_key(KioskKey k, double now_s, std::string_view key_name);
  // The bodies of the public entry points of the same names, run under guarded().
  void stick_inserted_now(const std::vector<StickEntry>& documents, double now_s, int unreadable);
  std::string unreadable_line(int unreadable) const;  // "" or the line that counts them, after a space
  void stick_removed_now(double now_s);
  void document_ready_now(const DocumentResult& result, double now_s);
  void capture_done_now(int shapes, double now_s);
  bool session_key(KioskKey k, double now_s);  // keys that act the same everywhere; true when handled
  void volume_key(int delta);
  void finish_key(double now_s);
  void language_key();
  void copy_key(double now_s);
  /// `tag` when it names another language than the visitor's (by language subtag), else "".
  std::string other_language(const std::string& tag) const;
  /// "In Français: " before a text in v_.reading_language, "" when it is the visitor's.
  std::string language_notice() const;
  /// "In English: " before a text in language `tag` (other_language's), "" for "".
  std::string language_notice(const std::string& tag) const;
  void describe_key();
  void reading_key(KioskKey k);  // the sentence and paragraph keys
  void repeat_key();
  bool reading() const;   // FlowView::reading
  void follow_reading();  // the place follows the sentence heard
  /// Reads from `at` to the end of its paragraph, after `before` (said first, in the same text).
  void read_from(ReadingPlace at, const std::string& before);
  /// A page's text still being read: the reading asked for starts with its first block, and goes on paragraph
  /// by paragraph to the end of the page, each once the one before has been heard and it has been read (tick).
  void read_more();
  /// "" or "About 9 minutes of text. …" and a space, for a text that long.
  std::string long_text_line(const std::string& text) const;
  /// "Paragraph 2 of 5." on a page of more than one whose whole text is known, else "".
  std::string paragraph_line(int paragraph) const;
  /// A load was asked for at `now_s`; `awaited`: another was awaited already (see the .cpp).
  void start_loading_clock(double now_s, bool awaited);
  void level_key(int delta);
  void warn(double idle_s);
  void pause_key();
  void help_key();
  void learn_key(KioskKey k, std::string_view key_name);
  void stray_key(std::string_view key_name);
  void tutorial_key(KioskKey k);
  void picture_key(KioskKey k);
  void activity(double now_s);
  /// Starts a visit: the welcome and the tutorial, in the default language unless `keep_language` (the
  /// Language key answering an invitation: the invitation's language).
  void wake(double now_s, bool keep_language);
  /// The attract invitation, in the next offered language in turn (language_offer after it).
  void invite();
  void end_session(double now_s);
  void start_tutorial();
  void show(int index, const std::string& before = {});
  void announce_picture(int shapes, const std::string& before);  // "Picture 2 of 5: ... It has 3 shapes."
  bool awaits_library_picture(int index) const;  // picture `index` of the library is the one asked for, still wanted
  void say(audio::MessageId id, std::initializer_list<audio::MessageArg> args = {});
  void say_brief(audio::MessageId id, std::initializer_list<audio::MessageArg> args = {});
  std::vector<std::string> help_groups()
      const;  // the help's templates, a few sentences each (every key; Capture's with a camera)
  int help_group_count() const;
  void say_help_group();  // group v_.help_group, where its keys lie, and how to go on
  std::string key_place_sentence(
      std::string_view key_name) const;                     // " The W key is ..." or "" (no place in the catalogue)
  std::string place() const;                                // where the visitor is, one sentence (a place_* message)
  std::string spoken_key(std::string_view key_name) const;  // "The Q key", "That key"
  void request(int document, int page, double now_s);
  void step_document(int delta, double now_s);
  std::string stick_summary() const;
  std::string document_name(const StickEntry& e) const;  // the title, else the file name, as spoken

  KioskEffects fx_;
  const audio::MessageCatalog& msg_;
  KioskFlowParams p_;
  Visit v_;
  bool learning_ = false;  // Help held down
  int failures_ = 0;
};

}  // namespace hk::app
