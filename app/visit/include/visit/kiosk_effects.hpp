#pragma once
/// @file kiosk_effects.hpp
/// What the visitor's flow (kiosk_flow.hpp) asks of the rest of the kiosk, one interface per object that
/// answers it:
///
/// | interface      | asks for                                              | answered in the kiosk by |
/// |----------------|-------------------------------------------------------|--------------------------|
/// | SpeechEffects  | say, Repeat, Pause, what is being heard, quiet hours  | Voice (voice.hpp)        |
/// | StageEffects   | practice shapes, Describe, Where, the page's text, level | Stage (stage.hpp)     |
/// | LibraryEffects | the library's pictures                                | LibraryDesk (library_desk.hpp) |
/// | StickEffects   | a USB stick's pages                                   | StickDesk (stick_desk.hpp) |
/// | CameraEffects  | a capture                                             | CameraDesk (camera_desk.hpp) |
/// | TourEffects    | Guide, and keys that stop a tour                      | TourDesk (tour_desk.hpp) |
/// | SessionEffects | volume, a new visitor                                 | KioskRuntime (kiosk_runtime.hpp) |
/// | CopyEffects    | a take-home copy of the picture (optional)            | CopyDesk (copy_desk.hpp) |
///
/// KioskEffects gathers one of each for the flow. Tests record the calls with one object that implements
/// them all (tests/support/every_effect.hpp), which converts to a KioskEffects by itself.

#include <cstdint>
#include <string>
#include <type_traits>
#include <vector>

#include "formats/picture_notes.hpp"
#include "pictures/picture_library.hpp"

namespace hk::app {

/// The text of the page shown, for reading by sentence and paragraph (read_aloud.hpp).
struct PageText {
  std::vector<std::string> paragraphs;  ///< its blocks of text in reading order; empty: no text
  int at_hand = -1;                     ///< the paragraph under the hand, −1 when none is
  std::string language;                 ///< the text's language (BCP 47) as its document says it, "" unknown
  /// False while the page's text is still being read (OCR): `paragraphs` are the blocks read so far, in reading
  /// order, and more may follow (at_hand is then −1).
  bool complete = true;
};

/// What is said, and what is heard of it.
class SpeechEffects {
 public:
  virtual ~SpeechEffects() = default;
  /// Speak `text` now, cutting off what is being said; Repeat says it again later.
  virtual void say(const std::string& text) = 0;
  /// Speak an acknowledgement ("Louder.", a key's name) now, cutting off what is being said; Repeat passes it
  /// over and says the text before it. Default: say().
  virtual void say_brief(const std::string& text) { say(text); }
  /// Say the last text said with say() again, from its start. False when there is none (nothing said).
  /// Default: nothing to repeat.
  virtual bool repeat() { return false; }
  /// Texts said with say() so far (a count that only grows): the flow knows whether what it said last is
  /// still the last text kept, or something else (a tour's line, a page's text arriving) has been said since.
  /// Default: 0.
  virtual std::uint64_t kept_texts() const { return 0; }
  /// Which piece (audio::speech_pieces, from 0) of the last text said with say() is being heard now; −1 when it
  /// is over, was cut off by anything said since, or nothing was said. Default: −1.
  virtual int heard_piece() const { return -1; }
  /// The last text said with say() was heard to its end: not cut off by anything said since, brief or not.
  /// Default: heard_piece() < 0.
  virtual bool heard_to_end() const { return heard_piece() < 0; }
  /// Speech is being heard (not paused). Default: never.
  virtual bool speaking() const { return false; }
  /// Hold the speech where it is; false when nothing is being said. Default: nothing is.
  virtual bool pause_speech() { return false; }
  /// Go on from a pause; false when speech is not paused. Default: never paused.
  virtual bool resume_speech() { return false; }
  /// Whether now is within the operator's quiet hours ([kiosk] quiet_hours): no spoken invitation. Default: no.
  virtual bool quiet_hours() const { return false; }
  /// How many languages are offered, the one in use (index, from 0) and the default each visit starts in.
  virtual int language_count() const { return 1; }
  virtual int language() const { return 0; }
  virtual int default_language() const { return 0; }
  /// Speaks and answers in language `index` from now on (the catalogue and the voice); out of range: nothing.
  virtual void set_language(int index) { (void)index; }
  /// As say(), but its pieces from `from_piece` up to (not including) `until_piece` (audio::speech_pieces; −1:
  /// to the end) in the voice of `language` (a BCP 47 tag): a document's text in its own language after the
  /// visitor's words before it, or what staff wrote in another language between the visitor's words.
  virtual void say_in(const std::string& text, int from_piece, const std::string& language, int until_piece = -1) {
    (void)from_piece;
    (void)language;
    (void)until_piece;
    say(text);
  }
  /// The name of language `tag` in itself ("Français") where the kiosk offers it; "" otherwise.
  virtual std::string language_name_of(const std::string& tag) const {
    (void)tag;
    return {};
  }
};

/// What is on the device and the screen, and what is said of it.
class StageEffects {
 public:
  virtual ~StageEffects() = default;
  /// Put a tutorial shape on the device.
  virtual void show_tutorial(TutorialShape shape) = 0;
  /// The title and description a person wrote for the picture shown (picture_notes.hpp); empty when none.
  virtual PictureNotes shown_notes() const { return {}; }
  /// A spoken description of what is shown, starting from where the hand is (describe.hpp).
  virtual std::string describe() = 0;
  /// "What is here": the shape or block of text under or nearest the hand and where the hand is, one or two
  /// sentences (describe.hpp, where_message). Default: nothing to say ("").
  virtual std::string where() { return {}; }
  /// The text of the page shown, paragraph by paragraph, and which is under the hand; while it is still being
  /// read, the blocks read so far (PageText::complete false). Default: no text.
  virtual PageText page_text() { return {}; }
  /// Level one finer (delta −1) or coarser (+1). Returns false at the limit (nothing changes). A change turns
  /// the level from hand speed off for the picture shown (it comes back with another picture).
  virtual bool change_level(int delta) = 0;
  /// Whether the level is chosen from hand speed now (Finer and Coarser then say, once, that they turn it
  /// off). Default: false.
  virtual bool auto_level() const { return false; }
};

/// The picture library.
class LibraryEffects {
 public:
  virtual ~LibraryEffects() = default;
  /// show_picture's answer while the picture is still being built: the picture felt before stays, and
  /// KioskFlow::picture_ready (or picture_failed) follows.
  static constexpr int kPicturePending = -1;
  /// Put picture `index` (0-based) on the device. Returns its number of shapes when it is on the device now
  /// (built ahead, or quick), else kPicturePending: it is built off the window thread, and the window layer
  /// calls KioskFlow::picture_ready or picture_failed when it is done. A newer request supersedes an older one.
  virtual int show_picture(int index) = 0;
  /// Pictures in the library (≥ 1).
  virtual int picture_count() const = 0;
  /// The visitor moves to library picture `index` from picture `from` (0-based, of the library as it is; `from` −1
  /// when they were on none): a new listing of the library folder that waited while a picture was felt is taken
  /// now. Returns the index, in the library from now on, of that same picture; when it is gone, of the one after
  /// `from` by file name (before it, for a step back), round the ends.
  virtual int moving_to(int index, int from) {
    (void)from;
    return index;
  }
};

/// A USB stick's documents.
class StickEffects {
 public:
  virtual ~StickEffects() = default;
  /// Start loading page `page` (from 1) of stick document `document` (0-based) off the window thread; when
  /// done, the window layer calls KioskFlow::document_ready. A newer request supersedes an older one.
  virtual void show_document(int document, int page) = 0;
  /// Drop the stick's listing (a new visitor must not browse the last one's stick).
  virtual void forget_stick() = 0;
};

/// The camera.
class CameraEffects {
 public:
  virtual ~CameraEffects() = default;
  /// The Capture key: start a guided camera capture off the window thread; the window layer then reports
  /// with KioskFlow::capture_advice / capture_done / capture_failed. False when there is no camera (nothing
  /// starts). Default: no camera.
  virtual bool start_capture() { return false; }
  /// Stop the capture under way (a key was pressed or the session ended); no report follows. Default: nothing.
  virtual void cancel_capture() {}
};

/// The guided tour.
class TourEffects {
 public:
  virtual ~TourEffects() = default;
  /// Any key that acts was pressed (before the flow acts on it): a guided tour that runs, or is about to,
  /// stops. Not called for Volume, nor for a key named in learning mode. Default: nothing.
  virtual void key_pressed() {}
  /// The Guide key: say that the hand will be guided, then lead the handle to the nearest shape not yet
  /// touched and round it, or, when the press stopped a running tour (key_pressed), say so. What is said is
  /// up to the implementation (the tour's end is reported later). Default: nothing.
  virtual void guide() {}
};

/// The visitor's session.
class SessionEffects {
 public:
  virtual ~SessionEffects() = default;
  /// Volume one step up (+1) or down (−1). Returns false at the limit.
  virtual bool change_volume(int delta) = 0;
  /// A new visitor: the operator's default settings (volume, level), speech stopped and forgotten.
  virtual void new_session() = 0;
};

/// What became of a copy, route by route ([copy] to: the printer, the visitor's stick, or both).
struct CopyReport {
  /// A route's outcome.
  enum class Route {
    NotAsked,        ///< [copy] to does not send copies this way
    Done,            ///< printed (queued) / saved on the stick
    Failed,          ///< the printer refused or is gone / the stick could not be written (a log line says why)
    NoStick,         ///< stick: none is in the kiosk
    Full,            ///< stick: no room on it
    WriteProtected,  ///< stick: its lock switch is on
    Format,          ///< stick: not FAT or exFAT
  };
  Route printed = Route::NotAsked;
  Route saved = Route::NotAsked;
  std::string printed_line;  ///< printed: [copy] printed_line (empty: the catalogue's)
  std::string folder;        ///< saved: the new folder's name on the stick
  /// Neither route gave the visitor a copy.
  bool nothing_made() const { return printed != Route::Done && saved != Route::Done; }
};

/// Take-home copies of the picture shown (a tactile graphic with braille).
class CopyEffects {
 public:
  virtual ~CopyEffects() = default;
  /// Copies are offered here ([copy] to is not "off" and names where they go).
  virtual bool copies_offered() const = 0;
  /// Copies go to the visitor's stick only ([copy] to = "stick") and no stick is in the kiosk.
  virtual bool stick_missing() const = 0;
  /// The day's copies ([copy] per_day) have all been made.
  virtual bool day_limit_reached() const = 0;
  /// Starts a copy of what is shown, in the visitor's language, off the window thread; the window layer then
  /// reports with KioskFlow::copy_finished. False when what is shown cannot be copied (nothing starts).
  virtual bool start_copy() = 0;
};

/// One of each effect, as the flow uses them. Each object outlives the flow.
struct KioskEffects {
  SpeechEffects& speech;
  StageEffects& stage;
  LibraryEffects& library;
  StickEffects& sticks;
  CameraEffects& camera;
  TourEffects& tour;
  SessionEffects& session;
  /// Take-home copies; none (null) where the kiosk offers none. Set after construction.
  CopyEffects* copies = nullptr;

  /// show_picture's answer while the picture is still being built (LibraryEffects::kPicturePending).
  static constexpr int kPicturePending = LibraryEffects::kPicturePending;

  /// Each effect from the object that answers it.
  KioskEffects(SpeechEffects& sp, StageEffects& st, LibraryEffects& li, StickEffects& sk, CameraEffects& ca,
               TourEffects& to, SessionEffects& se)
      : speech(sp), stage(st), library(li), sticks(sk), camera(ca), tour(to), session(se) {}
  /// Every effect from one object that implements them all (a test's recorder).
  template <class All,
            std::enable_if_t<std::is_base_of_v<SpeechEffects, All> && std::is_base_of_v<StageEffects, All> &&
                                 std::is_base_of_v<LibraryEffects, All> && std::is_base_of_v<StickEffects, All> &&
                                 std::is_base_of_v<CameraEffects, All> && std::is_base_of_v<TourEffects, All> &&
                                 std::is_base_of_v<SessionEffects, All>,
                             int> = 0>
  KioskEffects(All& all)  // NOLINT(google-explicit-constructor): a recorder stands for every effect
      : KioskEffects(all, all, all, all, all, all, all) {}
};

}  // namespace hk::app
