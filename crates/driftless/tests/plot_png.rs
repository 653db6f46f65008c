//! PNG output of `report::plot` (feature `png`).
#![cfg(feature = "png")]

use driftless::report::plot::{
    Figure, Line, LogLogPlot, PlotError, Series, embedded_font_advance_em, render_png,
    render_png_bytes, text_width,
};

fn plot() -> LogLogPlot {
    let taus: Vec<f64> = (0..16)
        .map(|i| 10f64.powf(-1.0 + 0.3 * f64::from(i)))
        .collect();
    let y: Vec<f64> = taus
        .iter()
        .map(|t| (0.04 / t + 1e-3 + 1e-5 * t).sqrt())
        .collect();
    LogLogPlot::new("Gyro", "τ (s)", "σ(τ) (deg/s)")
        .with_series(Series::new("X", taus, y))
        .with_line(
            Line::power_law("", 0.2, -0.5, 0.01, 1e4, 2)
                .dashed()
                .with_label("N = 0.2 deg/√s"),
        )
}

fn ihdr_size(png: &[u8]) -> (u32, u32) {
    assert_eq!(&png[12..16], b"IHDR");
    let be = |i: usize| u32::from_be_bytes([png[i], png[i + 1], png[i + 2], png[i + 3]]);
    (be(16), be(20))
}

#[test]
fn plot_png_signature_size_and_content() {
    let fig = Figure::single(plot());
    let bytes = render_png_bytes(&fig, 2.0).expect("png");
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
    assert_eq!(ihdr_size(&bytes), (1280, 960));

    let img = tiny_skia::Pixmap::decode_png(&bytes).expect("decodable");
    assert_eq!((img.width(), img.height()), (1280, 960));
    let px = img.pixels();
    let non_white = px
        .iter()
        .filter(|p| p.red() < 250 || p.green() < 250 || p.blue() < 250)
        .count();
    let dark = px
        .iter()
        .filter(|p| p.red() < 80 && p.green() < 80 && p.blue() < 80)
        .count();
    let frac = non_white as f64 / px.len() as f64;
    assert!(frac > 0.02 && frac < 0.6, "non-white fraction {frac}");
    assert!(dark > 2000, "text and frame must be dark: {dark}");
    // The series colour (Okabe–Ito blue) is present.
    assert!(
        px.iter()
            .any(|p| p.red() < 20 && (100..130).contains(&p.green()) && p.blue() > 160)
    );

    // Text is drawn: the top band (panel title only) has dark pixels.
    let w = img.width() as usize;
    let title_dark = px[..w * 50].iter().filter(|p| p.red() < 80).count();
    assert!(title_dark > 100, "title pixels: {title_dark}");
}

#[test]
fn plot_png_file_and_errors() {
    let fig = Figure::grid(vec![plot(), plot()], 2);
    let path = std::env::temp_dir().join("driftless_plot_test.png");
    render_png(&fig, &path).expect("write");
    let bytes = std::fs::read(&path).expect("read back");
    assert_eq!(ihdr_size(&bytes), (2560, 960));
    let _ = std::fs::remove_file(&path);

    let bad = std::path::Path::new("/nonexistent-dir/x.png");
    assert!(matches!(render_png(&fig, bad), Err(PlotError::Io { .. })));
    assert!(matches!(
        render_png_bytes(&fig, 1e6),
        Err(PlotError::BadRasterSize { .. })
    ));
    // Odd scales fall back to 1.
    let b = render_png_bytes(&Figure::single(plot()), f64::NAN).expect("png");
    assert_eq!(ihdr_size(&b), (640, 480));
}

#[test]
fn plot_text_metrics_match_embedded_font() {
    for c in (' '..='~').chain("⁰¹²³⁴⁵⁶⁷⁸⁹⁻√°±×·".chars()) {
        let font = embedded_font_advance_em(c).expect("glyph present");
        let table = text_width(&c.to_string(), 1.0);
        assert!(
            (font - table).abs() < 0.002,
            "{c:?}: font {font} table {table}"
        );
    }
}
