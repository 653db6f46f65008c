//! Text metrics without a font engine.
//!
//! Layout (axis margins, legend boxes, label collision tests) needs text
//! widths before anything is drawn, and must work without the `png` feature.
//! The widths below are the horizontal advances of DejaVu Sans — the font the
//! PNG renderer embeds and the first choice of the SVG `font-family` — in
//! thousandths of an em, for printable ASCII. A test behind the `png` feature
//! checks them against the embedded font. Browsers substituting another sans
//! font come within a few per cent, which the layout's padding absorbs.

/// Advances for `' '..='~'` in 1/1000 em.
const ASCII_ADVANCE: [u16; 95] = [
    318, 401, 460, 838, 636, 950, 780, 275, 390, 390, 500, 838, 318, 361, 318,
    337, // ' '..'/'
    636, 636, 636, 636, 636, 636, 636, 636, 636, 636, 337, 337, 838, 838, 838,
    531, // '0'..'?'
    1000, 684, 686, 698, 770, 632, 575, 775, 752, 295, 295, 656, 557, 863, 748,
    787, // '@'..'O'
    603, 787, 695, 635, 611, 732, 684, 989, 685, 611, 685, 390, 337, 390, 838,
    500, // 'P'..'_'
    500, 613, 635, 550, 635, 615, 352, 635, 634, 278, 278, 579, 278, 974, 634,
    612, // '`'..'o'
    635, 635, 411, 521, 392, 634, 592, 818, 592, 592, 525, 636, 337, 636, 838, // 'p'..'~'
];

/// Advance of one character in em.
pub(crate) fn char_advance_em(c: char) -> f64 {
    let u = c as u32;
    let milli = match c {
        ' '..='~' => ASCII_ADVANCE[(u - 0x20) as usize],
        '⁰' | '¹' | '²' | '³' | '⁴'..='⁹' => 401,
        '⁻' | '⁺' => 528,
        '√' => 637,
        '°' => 500,
        '±' | '×' | '÷' | '−' => 838,
        '·' => 318,
        '–' => 500,
        '—' => 1000,
        '\u{0}'..='\u{1f}' => 0,
        // Latin-1 / Greek / Cyrillic letters: close to the lower-case average.
        '\u{a0}'..='\u{4ff}' => 640,
        // CJK and other wide scripts.
        '\u{1100}'..='\u{115f}' | '\u{2e80}'..='\u{a4cf}' | '\u{ac00}'..='\u{d7a3}' => 1000,
        '\u{f900}'..='\u{faff}' | '\u{ff00}'..='\u{ff60}' => 1000,
        _ => 700,
    };
    f64::from(milli) / 1000.0
}

/// Width in px of `s` set at `size` px.
pub fn text_width(s: &str, size: f64) -> f64 {
    s.chars().map(char_advance_em).sum::<f64>() * size
}

/// Ascent of capitals / digits above the baseline, in em (DejaVu Sans: 0.73).
pub(crate) const CAP_HEIGHT_EM: f64 = 0.73;
/// Descent of p, g, y below the baseline, in em.
pub(crate) const DESCENT_EM: f64 = 0.24;
