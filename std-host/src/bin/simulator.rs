//! # The firmware's display, on the desktop
//!
//! The four cubes in an `embedded-graphics-simulator` window of 320x240
//! `Rgb565`, drawn as the firmware draws them: the core's strip adapter
//! ([`StripDrawer`]) in immediate mode, 16 rows of `Rgb565` and `u16`
//! depth at a time, into a `DrawTarget` (here the simulator's display).
//! A free camera starts at the scene's own camera: W/A/S/D move, Q/E move
//! down/up, drag with the mouse to look, R resets; the time the frame took
//! is drawn in the corner (embedded-graphics text).
//!
//! ```text
//! apt-get install libsdl2-dev
//! cargo run --release -p microraster-host --features simulator --bin simulator
//! ```
//!
//! With `EG_SIMULATOR_DUMP=file.png` it draws the first frame, without the
//! text, writes it at scale 1 and exits, with no window (the simulator
//! crate does that in `Window::update`). `.ci/simulator.sh` compares that
//! picture with the host renderer's, using the `compare` subcommand:
//!
//! ```text
//! simulator compare SIMULATOR.png HOST.png
//! ```
//!
//! which maps each host pixel (`Rgb888`) to `Rgb565` and back to `Rgb888`
//! with embedded-graphics' conversions (what the renderer and the simulator
//! do) and requires every pixel to be equal.

use embedded_graphics::mono_font::{ascii::FONT_6X10, MonoTextStyle};
use embedded_graphics::pixelcolor::{Rgb565, Rgb888, RgbColor};
use embedded_graphics::prelude::*;
use embedded_graphics::text::{Baseline, Text};
use embedded_graphics_simulator::sdl2::{Keycode, MouseButton};
use embedded_graphics_simulator::{
    OutputSettingsBuilder, SimulatorDisplay, SimulatorEvent, Window,
};
use microraster::math::radians;
use microraster::prelude::Submit;
use microraster::{Config, Mat4, StripDrawer, Vec3};
use microraster_scenes::cubes;
use std::collections::HashSet;
use std::process::ExitCode;
use std::time::Instant;

const WIDTH: u32 = 320;
const HEIGHT: u32 = 240;
const STRIP_ROWS: usize = 16;

/// Metres per second, and radians per pixel of mouse drag.
const SPEED: f32 = 3.0;
const LOOK: f32 = 0.005;

/// A free camera: position and viewing direction. It starts as the scene's
/// camera with the direction `target - eye`, so the first frame's matrices
/// are computed exactly as `cubes::mvps` computes them.
struct Camera {
    eye: Vec3,
    forward: Vec3,
    yaw: f32,
    pitch: f32,
}

impl Camera {
    fn scene() -> Camera {
        let eye = Vec3::from_array(cubes::CUBES_EYE);
        let forward = Vec3::from_array(cubes::CUBES_TARGET) - eye;
        let flat = (forward.x * forward.x + forward.z * forward.z).sqrt();
        Camera {
            eye,
            forward,
            yaw: forward.x.atan2(-forward.z),
            pitch: forward.y.atan2(flat),
        }
    }

    fn up() -> Vec3 {
        Vec3::from_array(cubes::CUBES_UP)
    }

    /// Turns by `dx`, `dy` pixels of mouse motion.
    fn look(&mut self, dx: i32, dy: i32) {
        let limit = radians(89.0);
        self.yaw += dx as f32 * LOOK;
        self.pitch = (self.pitch - dy as f32 * LOOK).clamp(-limit, limit);
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        self.forward = Vec3::new(sy * cp, sp, -cy * cp);
    }

    /// Moves by `along` the view direction, `right` and `up`.
    fn walk(&mut self, along: f32, right: f32, up: f32) {
        let f = self.forward.normalize();
        let r = f.cross(Camera::up()).normalize();
        self.eye = self.eye + f * along + r * right + Camera::up() * up;
    }

    /// The cubes' model-view-projection matrices, as `cubes::mvps` builds
    /// them (same operations, same order).
    fn mvps(&self) -> [Mat4; 4] {
        let aspect = WIDTH as f32 / HEIGHT as f32;
        let proj = Mat4::perspective(
            radians(cubes::CUBES_FOV_Y_DEG),
            aspect,
            cubes::CUBES_NEAR,
            cubes::CUBES_FAR,
        );
        let vp = proj * Mat4::look_at(self.eye, self.eye + self.forward, Camera::up());
        cubes::CUBE_MODELS.map(|ops| vp * cubes::model_matrix(&ops))
    }
}

/// The strip buffers and the drawing, as on the microcontroller.
struct Renderer {
    color: Vec<Rgb565>,
    depth: Vec<u16>,
}

impl Renderer {
    fn new() -> Renderer {
        let n = WIDTH as usize * STRIP_ROWS;
        Renderer {
            color: vec![Rgb565::BLACK; n],
            depth: vec![u16::MAX; n],
        }
    }

    fn draw(&mut self, display: &mut SimulatorDisplay<Rgb565>, mvps: &[Mat4; 4]) {
        let mut drawer = StripDrawer::new(&mut self.color, &mut self.depth[..], Rgb565::BLACK);
        let drawn = drawer.draw(display, Config::new(WIDTH, HEIGHT), |strip| {
            for (i, mvp) in mvps.iter().enumerate() {
                // A strip renderer stores nothing, so it cannot fill up.
                let id = (i * cubes::CUBE_INDICES.len()) as u32;
                strip
                    .submit_mesh(&cubes::MESH, mvp, id)
                    .expect("twelve triangles");
            }
        });
        // The simulator's display cannot fail, and the buffers fit.
        drawn.expect("drawing into the simulator display");
    }
}

/// The frame time and the keys, in the top-left corner.
fn overlay(display: &mut SimulatorDisplay<Rgb565>, frame_ms: f32) {
    let style = MonoTextStyle::new(&FONT_6X10, Rgb565::WHITE);
    let text = format!("{frame_ms:.2} ms/frame\nWASD QE move, drag look, R reset");
    // Text into the simulator's display cannot fail.
    let _ = Text::with_baseline(&text, Point::new(2, 2), style, Baseline::Top).draw(display);
}

fn run_window() -> ExitCode {
    let headless = std::env::var_os("EG_SIMULATOR_DUMP").is_some();
    let mut display = SimulatorDisplay::<Rgb565>::new(Size::new(WIDTH, HEIGHT));
    let settings = OutputSettingsBuilder::new()
        .scale(if headless { 1 } else { 2 })
        .build();
    let mut window = Window::new("microraster: four cubes, 320x240 Rgb565", &settings);
    let mut renderer = Renderer::new();
    let mut camera = Camera::scene();
    let mut held: HashSet<Keycode> = HashSet::new();
    let mut drag: Option<Point> = None;
    let mut last = Instant::now();

    loop {
        let start = Instant::now();
        renderer.draw(&mut display, &camera.mvps());
        let frame_ms = start.elapsed().as_secs_f32() * 1e3;
        if !headless {
            overlay(&mut display, frame_ms);
        }
        // With EG_SIMULATOR_DUMP this writes the picture and exits.
        window.update(&display);

        for event in window.events() {
            match event {
                SimulatorEvent::Quit => return ExitCode::SUCCESS,
                SimulatorEvent::KeyDown { keycode, .. } => {
                    if keycode == Keycode::R {
                        camera = Camera::scene();
                    }
                    held.insert(keycode);
                }
                SimulatorEvent::KeyUp { keycode, .. } => {
                    held.remove(&keycode);
                }
                SimulatorEvent::MouseButtonDown {
                    mouse_btn: MouseButton::Left,
                    point,
                } => drag = Some(point),
                SimulatorEvent::MouseButtonUp {
                    mouse_btn: MouseButton::Left,
                    ..
                } => drag = None,
                SimulatorEvent::MouseMove { point } => {
                    if let Some(from) = drag {
                        camera.look(point.x - from.x, point.y - from.y);
                        drag = Some(point);
                    }
                }
                _ => {}
            }
        }
        let dt = last.elapsed().as_secs_f32().min(0.1);
        last = Instant::now();
        let axis = |plus: Keycode, minus: Keycode| {
            (held.contains(&plus) as i32 - held.contains(&minus) as i32) as f32 * SPEED * dt
        };
        let (along, right, up) = (
            axis(Keycode::W, Keycode::S),
            axis(Keycode::D, Keycode::A),
            axis(Keycode::E, Keycode::Q),
        );
        if along != 0.0 || right != 0.0 || up != 0.0 {
            camera.walk(along, right, up);
        }
    }
}

/// Reads an 8-bit RGB or RGBA PNG as `Rgb888` pixels.
fn read_png(path: &str) -> Result<(u32, u32, Vec<Rgb888>), String> {
    let file = std::fs::File::open(path).map_err(|e| format!("{path}: {e}"))?;
    let mut decoder = png::Decoder::new(std::io::BufReader::new(file));
    decoder.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
    let mut reader = decoder.read_info().map_err(|e| format!("{path}: {e}"))?;
    let mut buf = vec![0; reader.output_buffer_size().unwrap_or(0)];
    let info = reader
        .next_frame(&mut buf)
        .map_err(|e| format!("{path}: {e}"))?;
    let channels = match info.color_type {
        png::ColorType::Rgb => 3,
        png::ColorType::Rgba => 4,
        other => return Err(format!("{path}: colour type {other:?}, expected RGB")),
    };
    let pixels = buf[..info.buffer_size()]
        .chunks_exact(channels)
        .map(|p| Rgb888::new(p[0], p[1], p[2]))
        .collect();
    Ok((info.width, info.height, pixels))
}

/// `simulator compare SIMULATOR.png HOST.png`: every pixel of the
/// simulator's picture must equal the host's quantized to `Rgb565` and
/// expanded back, both with embedded-graphics' `From` conversions.
fn compare(sim: &str, host: &str) -> Result<(), String> {
    let (sw, sh, s) = read_png(sim)?;
    let (hw, hh, h) = read_png(host)?;
    if (sw, sh) != (hw, hh) {
        return Err(format!("sizes differ: {sw}x{sh} and {hw}x{hh}"));
    }
    let mut differ = 0usize;
    let mut first = None;
    for (i, (a, b)) in s.iter().zip(&h).enumerate() {
        let want = Rgb888::from(Rgb565::from(*b));
        if *a != want {
            differ += 1;
            first.get_or_insert((i as u32 % sw, i as u32 / sw, *a, want));
        }
    }
    let covered = h.iter().filter(|p| **p != Rgb888::BLACK).count();
    match first {
        None => {
            println!(
                "simulator picture equals the host's through Rgb565: {sw}x{sh}, {covered} pixels not background"
            );
            Ok(())
        }
        Some((x, y, a, b)) => Err(format!(
            "{differ} of {} pixels differ; first at ({x}, {y}): simulator {a:?}, host through Rgb565 {b:?}",
            s.len()
        )),
    }
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.as_slice() {
        [] => run_window(),
        [cmd, sim, host] if cmd == "compare" => match compare(sim, host) {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => {
                eprintln!("simulator compare: {e}");
                ExitCode::FAILURE
            }
        },
        _ => {
            eprintln!("usage: simulator                      (window; EG_SIMULATOR_DUMP=file.png to dump)\n       simulator compare SIM.png HOST.png");
            ExitCode::from(2)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The first frame's matrices are the scene's, bit for bit.
    #[test]
    fn initial_camera_is_the_scenes() {
        let ours = Camera::scene().mvps();
        let theirs = cubes::mvps(WIDTH, HEIGHT);
        for (a, b) in ours.iter().zip(&theirs) {
            for r in 0..4 {
                assert_eq!(a.rows()[r].map(f32::to_bits), b.rows()[r].map(f32::to_bits));
            }
        }
    }

    #[test]
    fn overlay_writes_text_in_the_corner() {
        let mut d = SimulatorDisplay::<Rgb565>::new(Size::new(WIDTH, HEIGHT));
        overlay(&mut d, 12.5);
        let white = |x0: i32, x1: i32, y0: i32, y1: i32| {
            (y0..y1)
                .flat_map(|y| (x0..x1).map(move |x| Point::new(x, y)))
                .filter(|&p| d.get_pixel(p) == Rgb565::WHITE)
                .count()
        };
        assert!(white(0, 60, 0, 24) > 50);
        assert_eq!(white(0, 320, 30, 240), 0);
    }

    #[test]
    fn looking_keeps_pitch_in_range() {
        let mut c = Camera::scene();
        c.look(0, -100_000);
        assert!(c.forward.y < 1.0 && c.forward.y > 0.99);
        c.walk(1.0, 0.5, 0.25);
        assert!(c.eye.is_finite());
    }
}
