// The English source of everything the kiosk says: each message's key (its msgctxt in the catalogues) and
// English text (its msgid), in MessageId order, then the words Describe and Where build sentences from, the
// spoken key names and where the keys lie. xgettext reads this file (keywords NC_ and NPC_) to make
// audio-cues/po/haptic-kiosk.pot, the template every language's PO file translates.
//
// Placeholders, for translators: {picture} picture number, {pictures} number of pictures, {count} the number
// a counted message counts (its plural form follows it), {level} resolution level, {seconds} seconds left,
// {title} a picture's title, {description} a sentence or phrase built by the kiosk, {summary} what a USB stick
// holds (a phrase built from the summary_* words), {reason} why something cannot be read, {name} a document's
// file name or a named part of a picture, {page} / {pages} page number and count, {document} / {documents}
// document number and count, {text} words of a text, {place} where the visitor is (a place_* message),
// {shape} a shape's number or a shape said in words, {shapes} number of shapes, {where} where the hand is
// (a place_* word: far is away from the visitor, near towards them), {direction} a direction_* phrase, {key}
// the spoken name of a key pressed, {block} / {blocks} a text block's number and count. A placeholder ending
// in _key names one of the visitor's keys, as its spoken form (key_name.*): never write a key into a message,
// an operator may change it.
#include "audio/messages.hpp"

namespace hk::audio {
namespace {

constexpr MessageSource NC_(std::string_view key, std::string_view english) { return {key, english, {}}; }
constexpr MessageSource NPC_(std::string_view key, std::string_view one, std::string_view many) {
  return {key, one, many};
}

}  // namespace

const std::array<MessageSource, kMessageCount> kMessageSources{
    NC_("welcome", "Welcome. Feel the square with the handle. Press {next_key} to move on. Press {help_key} for help."),
    NC_("attract", "Hello. This is a touch picture. Move the handle, or press any key, to start."),
    NC_("help",
        "Move the handle slowly to feel the outlines. Press {next_key} for the next picture and {previous_key} for "
        "the one before. Press {where_key} to hear what is under your hand, and {describe_key} to hear what the "
        "picture holds. Press {repeat_key} to hear the last message again, and {pause_key} to pause the speech and "
        "go on. While a text is read, press {next_sentence_key} or {previous_sentence_key} to move by sentence, and "
        "{next_paragraph_key} or {previous_paragraph_key} by paragraph. Press {finer_key} for more detail and "
        "{coarser_key} for less. Press {volume_up_key} for louder and {volume_down_key} for quieter. Press "
        "{guide_key} to be led to a shape you have not touched yet. Press {tutorial_key} to practise with the "
        "shapes again, {language_key} for another language, and {finish_key} when you have finished. Hold "
        "{help_key} and press another key to learn what it does."),
    NPC_("picture_loaded", "Picture {picture} of {pictures}. It has one shape.",
         "Picture {picture} of {pictures}. It has {count} shapes."),
    NC_("picture_empty", "Picture {picture} of {pictures}. I found no shapes in it."),
    NPC_("picture_titled", "Picture {picture} of {pictures}: {title}. It has one shape.",
         "Picture {picture} of {pictures}: {title}. It has {count} shapes."),
    NC_("picture_titled_empty", "Picture {picture} of {pictures}: {title}. I found no shapes in it."),
    NC_("describe", "{description}"),
    NC_("level_finer", "More detail."),
    NC_("level_coarser", "Less detail."),
    NC_("level_finest", "This is the finest detail."),
    NC_("level_coarsest", "This is the coarsest detail."),
    NC_("volume_up", "Louder."),
    NC_("volume_down", "Quieter."),
    NC_("volume_limit", "That is the limit of the volume."),
    NC_("tutorial_start",
        "Let us practise. A square. Push hard on its wall to pass through it. Press {next_key} for the next shape."),
    NC_("tutorial_circle",
        "A circle. Press {where_key} to hear where your hand is. Press {next_key} for the next shape."),
    NC_("tutorial_triangle",
        "A triangle. Press {guide_key} to be led round it. Press {next_key} for the first picture."),
    NC_("tutorial_done",
        "Well done. Press {describe_key} to hear about a picture, {repeat_key} to hear it again. Here is the first "
        "picture."),
    NC_("timeout_warning",
        "Still there? Press any key for more time. In {seconds} seconds this visit ends and the picture is lost."),
    NC_("goodbye", "Thank you for visiting. Goodbye."),
    NC_("no_audio_device", "No sound device was found."),
    NC_("stick_inserted", "A USB stick with {summary}. Press {next_key} to go through them."),
    NC_("stick_empty", "I found no pictures and no PDF documents on this USB stick."),
    NC_("stick_removed", "The USB stick was taken out. Back to the picture library."),
    NC_("stick_unreadable", "I cannot read this USB stick. {reason}"),
    NC_("document_page", "Page {page} of {pages} of {name}. {description}"),
    NC_("document_picture", "Document {document} of {documents}, {name}. {description}"),
    NC_("document_unreadable", "{name} cannot be read. You still feel the picture before."),
    NC_("loading", "Loading."),
    NC_("text_block", "Text: {text}"),
    NC_("device_ready", "The handle is ready."),
    NC_("device_simulated", "No handle is connected. The kiosk runs on its simulated handle."),
    NC_("device_lost", "The handle is disconnected. Please wait while it reconnects."),
    NC_("device_back", "The handle works again."),
    NPC_("tour_remaining", "One shape not yet touched.", "{count} shapes not yet touched."),
    NC_("tour_all_touched", "You have touched every shape in this picture."),
    NC_("tour_stopped", "Tour stopped."),
    NC_("tour_nothing", "This picture has no shapes to be led to."),
    NC_("help_camera", "Press {capture_key} to feel a picture of your own under the camera."),
    NC_("camera_ready", "There is a camera: press {capture_key} to feel a picture of your own."),
    NC_("camera_none", "No camera was found."),
    NC_("capture_start",
        "Place the picture under the camera, face up. I will tell you how to move it, and take it when it lies "
        "still. Any key stops it."),
    NC_("capture_no_camera", "There is no camera on this kiosk."),
    NC_("capture_place", "Place the picture under the camera."),
    NC_("capture_too_dark", "It is too dark to see the picture."),
    NC_("capture_cut_off_top", "It is cut off at the top. Move it towards you."),
    NC_("capture_cut_off_bottom", "It is cut off at the bottom. Move it away from you."),
    NC_("capture_cut_off_left", "It is cut off on the left. Move it right."),
    NC_("capture_cut_off_right", "It is cut off on the right. Move it left."),
    NC_("capture_move_left", "Move it left."),
    NC_("capture_move_right", "Move it right."),
    NC_("capture_move_up", "Move it up, away from you."),
    NC_("capture_move_down", "Move it down, towards you."),
    NC_("capture_hold_still", "Hold still."),
    NPC_("captured", "Captured. It has one shape.", "Captured. It has {count} shapes."),
    NC_("captured_empty", "Captured, but I found no shapes in it."),
    NC_("capture_cancelled", "Capture stopped."),
    NC_("capture_failed", "The camera does not answer. Press {capture_key} to try again."),
    NC_("capture_timeout",
        "I could not take the picture: it did not lie still long enough. Press {capture_key} to try again."),
    NC_("help_brief",
        "{place} Press {next_key} to go on, {where_key} for what is here. {help_key} again gives every key."),
    NC_("place_tutorial", "Practising with a shape."),
    NC_("place_picture", "Picture {picture} of {pictures}."),
    NC_("place_document", "Page {page} of {pages}."),
    NC_("place_capture", "Your own picture from the camera."),
    NC_("key_help", "{help_key}: help. Press it twice for all the keys."),
    NC_("key_next", "{next_key}: the next picture."),
    NC_("key_previous", "{previous_key}: the picture before."),
    NC_("key_describe", "{describe_key}: what the picture holds."),
    NC_("key_finer", "{finer_key}: more detail."),
    NC_("key_coarser", "{coarser_key}: less detail."),
    NC_("key_volume_up", "{volume_up_key}: louder."),
    NC_("key_volume_down", "{volume_down_key}: quieter."),
    NC_("key_tutorial", "{tutorial_key}: practise with the shapes again."),
    NC_("key_guide",
        "{guide_key}: be led to a shape you have not touched; where the picture has named parts, to each part in "
        "turn."),
    NC_("key_capture", "{capture_key}: feel a picture of your own under the camera."),
    NC_("key_repeat", "{repeat_key}: hear the last message again."),
    NC_("key_pause", "{pause_key}: pause the speech, and go on."),
    NC_("key_where", "{where_key}: what is under your hand, and where it is."),
    NC_("key_finish", "{finish_key}: finish, and leave the kiosk for the next visitor."),
    NC_("key_other", "{key} does nothing here. Press {help_key} for help."),
    NC_("this_key", "That key"),
    NC_("nothing_to_pause", "Nothing is being said. Press {repeat_key} to hear the last message again."),
    NC_("nothing_to_repeat", "Nothing has been said yet."),
    NC_("where_on", "On shape {shape} of {shapes}: {description}. Your hand is {where}."),
    NC_("where_on_part", "On shape {shape} of {shapes}: {description}, at {name}. Your hand is {where}."),
    NC_("where_near", "Your hand is {where}. Shape {shape}, {description}, is {direction}."),
    NC_("where_inside", "Inside shape {shape} of {shapes}: {description}. Its edge is {direction}."),
    NC_("where_region", "In {name}. Your hand is {where}."),
    NC_("where_none", "There is no shape here. Your hand is {where}."),
    NC_("where_text", "On text block {block} of {blocks}, {where}. It begins: {text}"),
    NC_("sorry", "Sorry, that did not work. Everything is as it was."),
    NC_("tour_ask", "I will guide your hand to a shape. Hold the handle lightly."),
    NC_("tour_traced", "That was {description}."),
    NC_("tour_ask_part", "I will guide your hand to {name}. Hold the handle lightly."),
    NC_("touch_name", "{name}."),
    NC_("high_contrast_on", "High contrast on."),
    NC_("high_contrast_off", "High contrast off."),
    NC_("overlay_on", "The operator's overlay is on."),
    NC_("overlay_off", "The operator's overlay is off."),
    NC_("text_reading", "Reading the text."),
    NC_("text_ready", "The text is ready. {description}"),
    NC_("text_none", "No text was found."),
    NC_("text_unavailable", "The text could not be read."),
    NC_("device_not_home",
        "For the staff: the handle did not start at its home pose. Rest it there and press Calibrate in the "
        "operator's panel."),
    NC_("tour_stuck", "I could not lead your hand any further round this shape, so I have let go."),
    NC_("finish_ask", "Press {finish_key} again to finish your visit."),
    NC_("timeout_warning_stick",
        "Still there? Press any key for more time. In {seconds} seconds this visit ends and your place on the stick "
        "is lost."),
    NC_("level_manual", "Automatic detail is off until you press {next_key} or {previous_key} for another picture."),
    NPC_("files_unreadable", "One file cannot be read.", "{count} files cannot be read."),
    NC_("document_unreadable_alone", "{name} cannot be read."),
    NC_("read_aloud_warning",
        "People nearby can hear your document. Press {pause_key} to pause it, or {finish_key} to stop."),
    NPC_("long_text_minutes",
         "About a minute of text. Press {next_sentence_key} to skip a sentence, {next_paragraph_key} a paragraph.",
         "About {count} minutes of text. Press {next_sentence_key} to skip a sentence, {next_paragraph_key} a "
         "paragraph."),
    NC_("tutorial_push", "That is the square's wall. Push hard on it to pass through."),
    NC_("tutorial_no_levels",
        "A practice shape has one level of detail. {finer_key} and {coarser_key} work on the pictures."),
    NC_("far_near", "Far means away from you, near means towards you."),
    NC_("shape_square", "a square"),
    NC_("shape_circle", "a circle"),
    NC_("shape_triangle", "a triangle"),
    NC_("help_next", "Press {next_key} for more help, {previous_key} to go back."),
    NC_("help_last", "That is every key. Press {next_key} to go on."),
    NC_("key_place", "{key} is {place}."),
    NC_("key_next_sentence", "{next_sentence_key}: while a text is read, the next sentence."),
    NC_("key_previous_sentence", "{previous_sentence_key}: while a text is read, the sentence before."),
    NC_("key_next_paragraph", "{next_paragraph_key}: while a text is read, the next paragraph."),
    NC_("key_previous_paragraph", "{previous_paragraph_key}: while a text is read, the paragraph before."),
    NC_("reading_none", "There is no text here to read. Press {describe_key} to hear what the picture holds."),
    // TRANSLATORS: a reading key was pressed on a page whose text is still being recognised (OCR); the reading
    // starts by itself with the first words recognised.
    NC_("reading_soon", "The text is still being recognised. I will read it as soon as its first words are ready."),
    NC_("reading_start", "The start of the text."),
    NC_("reading_end", "That is the end of the text. Press {previous_sentence_key} to go back."),
    NC_("reading_paragraph", "Paragraph {block} of {blocks}."),
    NPC_("unclear_words", "unclear word", "{count} unclear words"),
    // TRANSLATORS: the language's own name, said in itself when a visitor chooses it.
    NC_("language_name", "English"),
    // TRANSLATORS: said in this language while the kiosk waits for a visitor, after attract.
    NC_("language_offer", "For English, press {language_key}."),
    NC_("key_language", "{language_key}: another language; each press gives the next one."),
    // TRANSLATORS: said before a text that is in another language than the visitor's: {name} is that
    // language's own name.
    NC_("other_language", "In {name}:"),
    NC_("key_copy", "{copy_key}: a copy of this picture to take home, pressed twice."),
    NC_("copy_confirm", "Press {copy_key} again within 10 seconds for a copy of this picture to take home."),
    NC_("copy_making", "Making your copy."),
    // TRANSLATORS: said when the copy has gone to the printer, unless staff wrote their own line.
    NC_("copy_printed", "Your copy is being printed. Ask for it at the front desk."),
    NC_("copy_not_set_up", "Copies to take home are not offered at this kiosk."),
    NC_("copy_nothing", "There is no picture to copy yet."),
    NPC_("copy_visit_limit", "You have had your copy for this visit.",
         "You have had the {count} copies of this visit."),
    NC_("copy_day_limit", "No more copies can be made today. Please ask a member of staff."),
    NC_("copy_failed", "Sorry, your copy could not be made. Please ask a member of staff."),
    // TRANSLATORS: the following four are printed and brailled on a take-home copy (a tactile graphic), not
    // spoken: the title of its key page, a shape without a name, the count of shapes left out, one not labelled.
    NC_("copy_key_title", "Key"),
    NC_("copy_shape", "shape {number}"),
    NC_("copy_left_out", "Shapes left out, too small or too close to another: {count}"),
    NC_("copy_not_labelled", "Not labelled on the picture: {name}"),
    // TRANSLATORS: the help's sentence for the Copy key, said when the kiosk offers copies.
    NC_("help_copy", "Press {copy_key} twice for a copy of the picture to take home."),
    // TRANSLATORS: said when the copy is on the visitor's USB stick: {folder} is the new folder's name
    // (copy_folder with the picture's title).
    NC_("copy_saved", "Your copy is on your stick, in the folder {folder}. You can take your stick now."),
    NC_("copy_no_stick", "Put your USB stick in first: the copy is saved on it."),
    NC_("copy_stick_full", "Your stick is full, so the copy could not be saved on it."),
    NC_("copy_stick_locked",
        "Your stick is write-protected, so the copy could not be saved on it. If it has a lock switch, slide it "
        "and try again."),
    NC_("copy_stick_format", "Your stick cannot be written here: only FAT and exFAT sticks can take a copy."),
    NC_("copy_stick_failed", "Sorry, the copy could not be saved on your stick. Please ask a member of staff."),
    // TRANSLATORS: the name of the folder a copy is saved in on the visitor's stick; {title} is the picture's
    // title. Not spoken by itself (copy_saved says it). Avoid the characters " * / : < > ? \ |.
    NC_("copy_folder", "{title} (tactile copy)"),
};

const std::array<MessageSource, kWordCount> kWordSources{
    // TRANSLATORS: the grammatical gender of the noun of look_* with the same ending, which chooses the
    // size_*, colour_* and shade_* words put in that look's {size} and {colour}: m, f or n (English has
    // none: n everywhere).
    NC_("gender_round", "n"),
    NC_("gender_oval", "n"),
    NC_("gender_square", "n"),
    NC_("gender_rectangle", "n"),
    NC_("gender_triangle", "n"),
    NC_("gender_star", "n"),
    NC_("gender_polygon", "n"),
    NC_("gender_straight", "n"),
    NC_("gender_bent", "n"),
    NC_("gender_curved", "n"),
    NC_("gender_shape", "n"),
    // TRANSLATORS: a shape as Describe and Where say it: {size} is a size_* word, {colour} a colour_* word
    // (or nothing, when the colour is not known: the kiosk then drops the extra space), both in the
    // gender of gender_* and the number of the form; {count} how many there are. The first form (one shape)
    // has an indefinite article.
    NPC_("look_round", "a {size} {colour} round shape", "{count} {size} {colour} round shapes"),
    NPC_("look_oval", "a {size} {colour} oval shape", "{count} {size} {colour} oval shapes"),
    NPC_("look_square", "a {size} {colour} square", "{count} {size} {colour} squares"),
    NPC_("look_rectangle", "a {size} {colour} rectangle", "{count} {size} {colour} rectangles"),
    NPC_("look_triangle", "a {size} {colour} triangle", "{count} {size} {colour} triangles"),
    NPC_("look_star", "a {size} {colour} star", "{count} {size} {colour} stars"),
    // TRANSLATORS: {corners} is a number from 4 to 8.
    NPC_("look_polygon", "a {size} {colour} {corners}-cornered shape",
         "{count} {size} {colour} {corners}-cornered shapes"),
    NPC_("look_straight", "a {size} {colour} straight line", "{count} {size} {colour} straight lines"),
    NPC_("look_bent", "a {size} {colour} bent line", "{count} {size} {colour} bent lines"),
    NPC_("look_curved", "a {size} {colour} curved line", "{count} {size} {colour} curved lines"),
    NPC_("look_shape", "a {size} {colour} shape", "{count} {size} {colour} shapes"),
    NC_("look_speck", "a speck"),
    // TRANSLATORS: sizes, for a noun of gender m (masculine), f (feminine) or n (neuter); one form for one
    // shape after the indefinite article, the other for several after a number.
    NPC_("size_large_m", "large", "large"),
    NPC_("size_large_f", "large", "large"),
    NPC_("size_large_n", "large", "large"),
    NPC_("size_medium_m", "medium", "medium"),
    NPC_("size_medium_f", "medium", "medium"),
    NPC_("size_medium_n", "medium", "medium"),
    NPC_("size_small_m", "small", "small"),
    NPC_("size_small_f", "small", "small"),
    NPC_("size_small_n", "small", "small"),
    // TRANSLATORS: the eleven basic colour terms, for a noun of gender m, f or n, as the sizes.
    NPC_("colour_black_m", "black", "black"),
    NPC_("colour_black_f", "black", "black"),
    NPC_("colour_black_n", "black", "black"),
    NPC_("colour_white_m", "white", "white"),
    NPC_("colour_white_f", "white", "white"),
    NPC_("colour_white_n", "white", "white"),
    NPC_("colour_grey_m", "grey", "grey"),
    NPC_("colour_grey_f", "grey", "grey"),
    NPC_("colour_grey_n", "grey", "grey"),
    NPC_("colour_red_m", "red", "red"),
    NPC_("colour_red_f", "red", "red"),
    NPC_("colour_red_n", "red", "red"),
    NPC_("colour_orange_m", "orange", "orange"),
    NPC_("colour_orange_f", "orange", "orange"),
    NPC_("colour_orange_n", "orange", "orange"),
    NPC_("colour_yellow_m", "yellow", "yellow"),
    NPC_("colour_yellow_f", "yellow", "yellow"),
    NPC_("colour_yellow_n", "yellow", "yellow"),
    NPC_("colour_green_m", "green", "green"),
    NPC_("colour_green_f", "green", "green"),
    NPC_("colour_green_n", "green", "green"),
    NPC_("colour_blue_m", "blue", "blue"),
    NPC_("colour_blue_f", "blue", "blue"),
    NPC_("colour_blue_n", "blue", "blue"),
    NPC_("colour_purple_m", "purple", "purple"),
    NPC_("colour_purple_f", "purple", "purple"),
    NPC_("colour_purple_n", "purple", "purple"),
    NPC_("colour_pink_m", "pink", "pink"),
    NPC_("colour_pink_f", "pink", "pink"),
    NPC_("colour_pink_n", "pink", "pink"),
    NPC_("colour_brown_m", "brown", "brown"),
    NPC_("colour_brown_f", "brown", "brown"),
    NPC_("colour_brown_n", "brown", "brown"),
    // TRANSLATORS: a light or dark colour: {colour} is the colour_* word in the noun's gender and number.
    NC_("shade_light", "light {colour}"),
    NC_("shade_dark", "dark {colour}"),
    // TRANSLATORS: where a shape or the hand is, in a 3 x 3 grid: far is away from the visitor, near
    // towards them. Said after a shape ("a small square at the far left") and after "Your hand is".
    NC_("place_far_left", "at the far left"),
    NC_("place_far_middle", "in the far middle"),
    NC_("place_far_right", "at the far right"),
    NC_("place_left", "on the left"),
    NC_("place_middle", "in the middle"),
    NC_("place_right", "on the right"),
    NC_("place_near_left", "at the near left"),
    NC_("place_near_middle", "in the near middle"),
    NC_("place_near_right", "at the near right"),
    // TRANSLATORS: the place of several alike shapes that lie in different places.
    NC_("place_across", "across the picture"),
    // TRANSLATORS: which way a shape lies from the hand, after a distance ("3 cm to your right").
    NC_("way_right", "to your right"),
    NC_("way_far_right", "farther away, to your right"),
    NC_("way_far", "farther away"),
    NC_("way_far_left", "farther away, to your left"),
    NC_("way_left", "to your left"),
    NC_("way_near_left", "nearer to you, to your left"),
    NC_("way_near", "nearer to you"),
    NC_("way_near_right", "nearer to you, to your right"),
    NC_("distance_under_cm", "less than a centimetre"),
    NPC_("distance_cm", "{count} cm", "{count} cm"),
    // TRANSLATORS: {distance} is distance_*, {way} a way_* phrase.
    NC_("direction", "{distance} {way}"),
    NC_("scene_none", "There are no shapes in this picture."),
    NPC_("scene_count", "One shape.", "{count} shapes."),
    // TRANSLATORS: Describe's list of shapes, nearest the hand first; {list} is built with list_*.
    NC_("scene_nearest", "Nearest your hand, {list}"),
    // TRANSLATORS: the shapes without a name, after the named parts.
    NC_("scene_also", "Also {list}"),
    // TRANSLATORS: a list of shapes or parts is built item by item: list_next adds an item, list_last the
    // last one; list_two joins just two, inside a shape.
    NC_("list_next", "{list}, {item}"),
    NC_("list_last", "{list}, and {item}"),
    NC_("list_two", "{first} and {second}"),
    NC_("list_end", "{list}."),
    NPC_("list_rest", "{list}, and one more.", "{list}, and {count} more."),
    NPC_("list_rest_smaller", "{list}, and one more, smaller.", "{list}, and {count} more, smaller ones."),
    // TRANSLATORS: {shape} is a look_* phrase or a named part, {place} a place_* word.
    NC_("shape_place", "{shape} {place}"),
    // TRANSLATORS: {inside} is a look_* phrase, list_two of two, or inside_many.
    NC_("shape_inside", "{shape} with {inside} inside it"),
    NC_("shape_inside_place", "{shape} with {inside} inside it, {place}"),
    NPC_("inside_many", "{count} smaller shape", "{count} smaller shapes"),
    // TRANSLATORS: a practice shape (shape_square, …) and its place, as a sentence.
    NC_("shape_at", "{shape}, {place}."),
    NC_("shapes_none", "I found no shapes in it."),
    NPC_("shapes", "It has one shape.", "It has {count} shapes."),
    // TRANSLATORS: what a document page holds: {blocks} is page_blocks or page_no_text, {figures}
    // page_figures or page_no_figures.
    NC_("page_holds", "It has {blocks} and {figures}."),
    NPC_("page_blocks", "one block of text", "{count} blocks of text"),
    NC_("page_no_text", "no text"),
    NPC_("page_figures", "one figure", "{count} figures"),
    NC_("page_no_figures", "no figures"),
    // TRANSLATORS: a part of a picture that staff named in this language, when the name starts with a small
    // letter and has no article of its own ("left wing"); write just {name} where no article fits.
    NC_("name_the", "the {name}"),
    // TRANSLATORS: one of several shapes that share a plural name ("one of the white spots").
    NC_("name_one_of", "one of {name}"),
    // TRANSLATORS: one of several shapes that share a name ("part of the left wing").
    NC_("name_part_of", "part of {name}"),
    NC_("guess_face", "something that could be a face"),
    // TRANSLATORS: a part named by the first words of the text written on it.
    NC_("guess_text", "text: {text}"),
    // TRANSLATORS: the names of the languages the kiosk speaks, as said in other_language's {name} ("In French:"),
    // in this language and as they read there.
    NC_("language_en", "English"),
    NC_("language_fr", "French"),
    NC_("language_de", "German"),
    NC_("language_es", "Spanish"),
    // TRANSLATORS: what a USB stick holds, in stick_inserted's {summary}: summary_all is "{documents}:
    // {what}", {what} one of summary_pictures_and_pdfs, the summary_pictures phrase, or a summary_pdf phrase.
    NC_("summary_all", "{documents}: {what}"),
    NPC_("summary_documents", "one document", "{count} documents"),
    NPC_("summary_pictures", "a picture", "{count} pictures"),
    NPC_("summary_pages", "one page", "{count} pages"),
    // TRANSLATORS: {pages} is summary_pages.
    NC_("summary_one_pdf", "a PDF of {pages}"),
    NPC_("summary_pdfs", "one PDF of {pages} in all", "{count} PDFs of {pages} in all"),
    NC_("summary_capped", "{pdfs} (the first {count} pages of each can be read)"),
    NC_("summary_pictures_and_pdfs", "{pictures} and {pdfs}"),
};

// TRANSLATORS: key_name.* is how a key of the keyboard is said, as it reads after "Press" ("Press the Up
// arrow"); the kiosk makes its first letter a capital where it starts a sentence.
const std::array<MessageSource, kKeyNameCount> kKeyNameSources{
    NC_("key_name.F1", "F1"),
    NC_("key_name.F2", "F2"),
    NC_("key_name.F3", "F3"),
    NC_("key_name.F4", "F4"),
    NC_("key_name.F5", "F5"),
    NC_("key_name.F6", "F6"),
    NC_("key_name.F7", "F7"),
    NC_("key_name.F8", "F8"),
    NC_("key_name.F9", "F9"),
    NC_("key_name.F10", "F10"),
    NC_("key_name.F11", "F11"),
    NC_("key_name.F12", "F12"),
    NC_("key_name.A", "the A key"),
    NC_("key_name.B", "the B key"),
    NC_("key_name.D", "the D key"),
    NC_("key_name.E", "the E key"),
    NC_("key_name.F", "the F key"),
    NC_("key_name.G", "the G key"),
    NC_("key_name.H", "the H key"),
    NC_("key_name.I", "the I key"),
    NC_("key_name.J", "the J key"),
    NC_("key_name.K", "the K key"),
    NC_("key_name.L", "the L key"),
    NC_("key_name.M", "the M key"),
    NC_("key_name.N", "the N key"),
    NC_("key_name.P", "the P key"),
    NC_("key_name.Q", "the Q key"),
    NC_("key_name.R", "the R key"),
    NC_("key_name.S", "the S key"),
    NC_("key_name.T", "the T key"),
    NC_("key_name.U", "the U key"),
    NC_("key_name.V", "the V key"),
    NC_("key_name.W", "the W key"),
    NC_("key_name.X", "the X key"),
    NC_("key_name.Y", "the Y key"),
    NC_("key_name.Z", "the Z key"),
    NC_("key_name.0", "the 0 key"),
    NC_("key_name.1", "the 1 key"),
    NC_("key_name.2", "the 2 key"),
    NC_("key_name.3", "the 3 key"),
    NC_("key_name.4", "the 4 key"),
    NC_("key_name.5", "the 5 key"),
    NC_("key_name.6", "the 6 key"),
    NC_("key_name.7", "the 7 key"),
    NC_("key_name.8", "the 8 key"),
    NC_("key_name.9", "the 9 key"),
    NC_("key_name.SPACE", "the space bar"),
    NC_("key_name.ENTER", "the Enter key"),
    NC_("key_name.TAB", "the Tab key"),
    NC_("key_name.BACKSPACE", "the Backspace key"),
    NC_("key_name.LEFT", "the Left arrow"),
    NC_("key_name.RIGHT", "the Right arrow"),
    NC_("key_name.UP", "the Up arrow"),
    NC_("key_name.DOWN", "the Down arrow"),
    NC_("key_name.PAGE_UP", "Page Up"),
    NC_("key_name.PAGE_DOWN", "Page Down"),
    NC_("key_name.HOME", "the Home key"),
    NC_("key_name.END", "the End key"),
    NC_("key_name.INSERT", "the Insert key"),
    NC_("key_name.DELETE", "the Delete key"),
    NC_("key_name.MINUS", "the minus key"),
    NC_("key_name.EQUAL", "the equals key"),
    NC_("key_name.KP_0", "keypad 0"),
    NC_("key_name.KP_1", "keypad 1"),
    NC_("key_name.KP_2", "keypad 2"),
    NC_("key_name.KP_3", "keypad 3"),
    NC_("key_name.KP_4", "keypad 4"),
    NC_("key_name.KP_5", "keypad 5"),
    NC_("key_name.KP_6", "keypad 6"),
    NC_("key_name.KP_7", "keypad 7"),
    NC_("key_name.KP_8", "keypad 8"),
    NC_("key_name.KP_9", "keypad 9"),
    NC_("key_name.KP_ADD", "keypad plus"),
    NC_("key_name.KP_SUBTRACT", "keypad minus"),
    NC_("key_name.KP_ENTER", "keypad Enter"),
};

// TRANSLATORS: key_place.* is where a key lies on a standard PC keyboard, for a visitor who finds keys by
// touch ("The Right arrow is the right one of the four arrow keys, at the bottom right of the keyboard.").
const std::array<MessageSource, kKeyPlaceCount> kKeyPlaceSources{
    NC_("key_place.F1", "in the row along the top of the keyboard, the second key from the left"),
    NC_("key_place.RIGHT", "the right one of the four arrow keys, at the bottom right of the keyboard"),
    NC_("key_place.LEFT", "the left one of the four arrow keys, at the bottom right of the keyboard"),
    NC_("key_place.UP", "the top one of the four arrow keys, at the bottom right of the keyboard"),
    NC_("key_place.DOWN", "the middle one of the three bottom arrow keys, at the bottom right of the keyboard"),
    NC_("key_place.W", "in the top row of letters, the second from the left"),
    NC_("key_place.D", "in the middle row of letters, the third from the left"),
    NC_("key_place.R", "in the top row of letters, the fourth from the left"),
    NC_("key_place.T", "in the top row of letters, the fifth from the left"),
    NC_("key_place.P", "in the top row of letters, the tenth from the left"),
    NC_("key_place.G", "in the middle row of letters, the fifth from the left"),
    NC_("key_place.J", "in the middle row of letters, the seventh from the left; it has a small raised bar"),
    NC_("key_place.K",
        "in the middle row of letters, the eighth from the left, just right of the key with the raised bar"),
    NC_("key_place.L", "in the middle row of letters, the ninth from the left"),
    NC_("key_place.U", "in the top row of letters, the seventh from the left"),
    NC_("key_place.I", "in the top row of letters, the eighth from the left"),
    NC_("key_place.SPACE", "the long bar at the front of the keyboard"),
    NC_("key_place.HOME", "in the block of six keys above the arrow keys, the middle of its top row"),
    NC_("key_place.PAGE_UP", "in the block of six keys above the arrow keys, at its top right"),
    NC_("key_place.END", "in the block of six keys above the arrow keys, the middle of its bottom row"),
    NC_("key_place.PAGE_DOWN", "in the block of six keys above the arrow keys, at its bottom right"),
};

}  // namespace hk::audio
