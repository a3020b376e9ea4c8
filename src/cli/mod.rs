//! Command definitions and dispatch. Each subcommand lives in its own file and only turns
//! arguments into library calls and library results into text, JSON and exit codes.
//!
//! Exit codes: 0 success; 1 the operation ran and failed (e.g. `validate` found problems);
//! 2 bad usage or unreadable/unparseable input.

use std::process::ExitCode;

use clap::{Parser, Subcommand};
use fbakit::error::Diagnostic;

/// `println!` for lines that quote file content: control characters escaped (see
/// [`print_text`]). Defined before the submodules so they can use it.
macro_rules! outln {
    ($($arg:tt)*) => {
        $crate::cli::print_text(&format!("{}\n", format_args!($($arg)*)))
    };
}

mod candide;
mod clone;
mod docs;
pub mod face;
pub mod face_export;
pub(crate) mod face_from_rig;
mod face_subdivide;
pub mod fap;
mod fap_arkit;
mod fapu;
mod fp;
mod inputs;
mod lipsync;
pub mod play;
mod render;
mod rig;
mod show;
mod snapshot;
mod speak;
mod view;

/// A cloning method on the command line (`--method fmc|rbf|fit`). `clone`, `eval self-clone`,
/// `grid` and `demo` share one default, [`MethodArg::default`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum MethodArg {
    /// Facial motion cloning (Pandzic 2003).
    Fmc,
    /// RBF cloning (Fratarcangeli & Schaerf 2005).
    Rbf,
    /// Dense correspondence by non-rigid registration (fbakit's `fit`).
    Fit,
}

impl Default for MethodArg {
    /// The library's default method ([`fbakit::clone::face::Method::default`]).
    fn default() -> Self {
        match fbakit::clone::face::Method::default() {
            fbakit::clone::face::Method::Fmc => MethodArg::Fmc,
            fbakit::clone::face::Method::Rbf => MethodArg::Rbf,
            fbakit::clone::face::Method::Fit => MethodArg::Fit,
        }
    }
}

impl std::fmt::Display for MethodArg {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(fbakit::clone::face::Method::from(*self).name())
    }
}

impl From<MethodArg> for fbakit::clone::face::Method {
    fn from(m: MethodArg) -> fbakit::clone::face::Method {
        match m {
            MethodArg::Fmc => fbakit::clone::face::Method::Fmc,
            MethodArg::Rbf => fbakit::clone::face::Method::Rbf,
            MethodArg::Fit => fbakit::clone::face::Method::Fit,
        }
    }
}

/// Parses an output frame rate (`--fps` of `render` and `speak`): finite, 0 < fps <= 240.
pub fn parse_fps(s: &str) -> std::result::Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 && v <= 240.0 => Ok(v),
        _ => Err(format!("`{s}` is not a frame rate between 0 and 240")),
    }
}

/// Exit code for success.
pub const EXIT_OK: u8 = 0;
/// Exit code for a failed operation.
pub const EXIT_FAILURE: u8 = 1;
/// Exit code for bad usage or bad input.
pub const EXIT_BAD_INPUT: u8 = 2;

#[derive(Debug, Parser)]
#[command(
    name = "fbakit",
    version,
    about = "MPEG-4 facial animation: FAP streams, feature points, FATs, cloning, playback, \
             video, speech",
    long_about = "fbakit reads, checks and writes MPEG-4 Face Animation data (FAP streams, \
                  feature points and FAP units, faces with Facial Animation Tables in VRML, \
                  OBJ, CANDIDE-3 and glTF, blendshape rigs), clones a face's FAT onto \
                  another face, and plays FAP streams as glTF, pictures, video or a one-file \
                  HTML viewer; `speak` turns typed text into a viseme stream.\n\n\
                  Every command takes --json (errors are then JSON on stderr too). Warnings \
                  go to stderr. Exit codes: 0 ok, 1 the operation failed (e.g. validation \
                  found problems, an output could not be written), 2 bad usage or bad input.",
    after_help = "Examples:\n  \
                  fbakit demo                                       the whole pipeline on the bundled faces\n  \
                  fbakit face info alma                             a face: meshes, feature points, FAPU, FAT\n  \
                  fbakit fap info samples/speech.fap                a FAP stream\n  \
                  fbakit clone alma bruno.wrl -o bruno-fat.wrl      clone a FAT onto another face\n  \
                  fbakit play alma samples/speech.fap -o a.glb      play a stream as animated glTF\n  \
                  fbakit view alma samples/speech.fap -o a.html     a viewer page that plays on load\n  \
                  fbakit speak \"Hello world\" -o hi.mp4              a real head says what you type, with sound\n  \
                  fbakit lipsync v.wav --text-file v.txt -o v.mp4  a real head says your recording\n  \
                  fbakit render alma s.fap --audio s.wav -o s.mp4   a stream (and its sound) as video\n  \
                  fbakit face from-rig RIG --fp fp.csv -o face.wrl  a FAP-compliant FAT from ARKit shapes\n  \
                  fbakit completions bash > fbakit.bash             shell completions (man: fbakit man -o DIR)\n\n\
                  `fbakit COMMAND --help` shows each command's options and examples."
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Print the MPEG-4 FAP table (number, name, FAPU, direction, feature point).
    #[command(after_help = "Example:\n  fbakit spec faps --json")]
    Spec(SpecArgs),
    /// Print the six FAP units (IRISD, ES, ENS, MNS, MW, AU) of a face from its feature points.
    #[command(
        long_about = "Print the six FAP units of a face: each neutral distance X0 and the unit \
                      X0/1024 (AU is fixed at 1e-5 rad). Explicit FAPU distances in the file \
                      (Xface <fapu>, fbakit <fapu>) are used as they are (\"from file\"); \
                      otherwise they are measured on the feature points with the standard's \
                      definitions (\"from feature points\"): IRISD0 = 3.1.y - 3.3.y, \
                      ES0 = 3.5.x - 3.6.x, ENS0 = 3.5.y - 9.15.y, MNS0 = 9.15.y - 2.2.y, \
                      MW0 = 8.3.x - 8.4.x.",
        after_help = "Examples:\n  fbakit fapu samples/feature-points-example.xml\n  fbakit fapu alice.fdp --json"
    )]
    Fapu(fapu::FapuArgs),
    /// Feature-point files from landmarks (iBUG-68, MediaPipe-468).
    #[command(
        subcommand,
        after_help = "Example:\n  fbakit fp from-landmarks generic_neutral_mesh.obj --ibug68 vertex_indices.json -o fp.csv"
    )]
    Fp(fp::FpCommand),
    /// Inspect, validate and convert ASCII FAP streams (`.fap`, `.json`).
    #[command(
        subcommand,
        after_help = "Examples:\n  fbakit fap info samples/speech.fap\n  \
                                        fbakit fap validate samples/lowlevel.fap\n  \
                                        fbakit fap convert samples/speech.fap speech.json"
    )]
    Fap(fap::FapCommand),
    /// Play a FAP stream on a face: animated glTF (.glb/.gltf), OBJ or PNG frames, a PNG sheet.
    #[command(
        long_about = "Play a FAP stream on a face with its Facial Animation Tables and write \
                      the result: OUT ending in .glb or .gltf gives an animated glTF (morph \
                      targets + node rotations); a directory (or --format obj) gives one OBJ \
                      per frame (frame_00000.obj, ...) and frames.json; OUT ending in .png \
                      gives a contact sheet of --sheet-frames frames (or, with --turntable K, \
                      K views around the first frame); a directory with --format png gives \
                      one PNG per frame (frame_00000.png, ...). FAPs not sent in a \
                      frame hold their last value. FACE is a VRML face file or `alma` / \
                      `bruno` (built-in faces). FAPs, visemes and expressions the face has no \
                      table for are reported.",
        after_help = "Examples:\n  fbakit play alma samples/speech.fap -o speech.glb\n  \
                      fbakit play bruno samples/lowlevel.fap -o frames/ --fps 50 --frames 0..25\n  \
                      fbakit play alma samples/speech.fap -o sheet.png --sheet-frames 6 --size 256x256\n  \
                      fbakit play bruno samples/speech.fap -o turn.png --turntable 8\n  \
                      fbakit play alma samples/speech.fap -o pngs/ --format png --frames 0..10"
    )]
    Play(play::PlayArgs),
    /// Inspect, validate and convert face models; build them from morph sets and back.
    #[command(
        subcommand,
        after_help = "Examples:\n  fbakit face info samples/faces/alma.wrl.gz\n  \
                      fbakit face validate face.wrl\n  \
                      fbakit face convert head.obj head.wrl --fp head.csv\n  \
                      fbakit face from-morphs neutral.obj morphs/ --fp neutral.csv -o face.wrl\n  \
                      fbakit face to-morphs face.wrl morphs/"
    )]
    Face(face::FaceCommand),
    /// Build an MPEG-4 face with a FAT from the CANDIDE-3 model (.wfm) and its feature-point table.
    #[command(
        long_about = "Build an MPEG-4 face with a FAT from the CANDIDE-3 model: one mesh `candide`, feature points bound to its vertices, FAPU measured on the shaped face, and one table per FAP unit of the model (rate = the unit's direction × the face's FAPU, borders 0 1024, linear beyond). FAPs 23-30 (eyeballs, pupils: translations without a FAPU in the model) and the action unit vectors get no table.",
        after_help = "Example:\n  fbakit candide candide3.wfm --fp feature-points.csv \
                      --shape \"Mouth width=0.3,Eyes, width=0.2\" -o candide.wrl"
    )]
    Candide(candide::CandideArgs),
    /// Write a bundled procedural face (alma or bruno) with its full FAT.
    #[command(
        after_help = "Examples:\n  fbakit sample alma -o alma.wrl\n  fbakit sample bruno -o bruno.wrl.gz"
    )]
    Sample(candide::SampleArgs),
    /// Clone the facial animation (FAT) of a source face onto a target face.
    #[command(
        long_about = "Clone the Facial Animation Tables of SOURCE onto TARGET: the skin by \
                      dense correspondence from a landmark-guided non-rigid registration \
                      (fit, the default), facial motion cloning (fmc, Pandzic 2003) or RBF \
                      cloning (rbf, Fratarcangeli & Schaerf 2005), eyes, teeth, tongue and \
                      head by their transforms. Faces are VRML face files, or OBJ meshes with a \
                      feature-point file. The target comes back in its own layout: every mesh \
                      with its vertices in their order (eyes and teeth inside one mesh move by \
                      per-vertex tables); an OBJ target cloned to DIR/ or .obj comes back as \
                      its own file plus one OBJ per morph target (shape keys). Exit codes: 0 ok, 2 bad usage or input (including \
                      missing feature points), 1 other failures.",
        after_help = "Examples:\n  fbakit clone alma.wrl bruno.wrl -o bruno-animated.wrl\n  \
                      fbakit clone alma.wrl head.obj --fp-target head.fdp -o head.wrl --method rbf --report\n  \
                      fbakit clone alma.wrl bruno.wrl -o out.wrl --json > report.json\n  \
                      fbakit clone alma bruno -o bruno-arkit.glb --method rbf --names arkit\n  \
                      fbakit clone alma head.obj --fp-target fp.csv -o shapes/ --names arkit\n  \
                      fbakit clone alma ict -o ict-blinks.glb -v --lid-cover on"
    )]
    Clone(clone::CloneArgs),
    /// Quality figures of a face's FAT (compliance, self-cloning error).
    #[command(
        subcommand,
        after_help = "Examples:\n  fbakit eval compliance bruno-animated.wrl\n  \
                      fbakit eval self-clone alma.wrl --method rbf --json"
    )]
    Eval(clone::EvalCommand),
    /// Render the cloning grid: every face's FAT cloned onto every other face, one pose.
    #[command(
        long_about = "Render the cloning grid (Pandzic 2003, Figure 11): rows are source faces, \
                      columns target faces; cell (i, j) is face j without its FAT, animated \
                      with the FAT cloned from face i, showing --key at --value. The diagonal \
                      shows each face with its own FAT. FACE is a VRML face file (.wrl, \
                      .wrl.gz) or `alma` / `bruno`.",
        after_help = "Examples:\n  fbakit grid alma bruno -o grid.png\n  \
                      fbakit grid alma bruno --key open_jaw --value 400 --method rbf -o jaw.png\n  \
                      fbakit grid alma.wrl bruno.wrl --key viseme_7 -o v7.png"
    )]
    Grid(show::GridArgs),
    /// Run the end-to-end demo on the bundled samples (clone, play, render, measure).
    #[command(
        long_about = "Run the end-to-end demo on the bundled samples. It clones three ways: \
                      the real ICT head's FAT (built from its ARKit shapes) onto a second real \
                      head, alma's FAT onto bruno (stripped to meshes and feature points) and \
                      alma's onto the ICT head; plays samples/speech.fap on every face; writes \
                      bruno-cloned.wrl, one animated .glb per face, contact-sheet.png and \
                      cloning-grid.png into --out (default ./fbakit-demo); then prints one table \
                      of quality figures (FAP compliance, error against the target's true FAT \
                      where it is known, self-clone error) and grouped warnings. Run it from \
                      the fbakit checkout (it finds samples/ there, or beside the sources).",
        after_help = "Examples:\n  fbakit demo\n  fbakit demo --out /tmp/demo --method rbf --json"
    )]
    Demo(show::DemoArgs),
    /// Write one self-contained HTML page that plays a FAP stream on a face, with FAP sliders.
    #[command(
        long_about = "Write one self-contained HTML page (three.js, the face as an animated \
                      glb and the viewer script all inside; works offline from file://). It \
                      plays STREAM on FACE looping, with play/pause, a time scrubber and \
                      speed; a panel of FAP sliders grouped as the standard groups them, in \
                      FAPU, poses the face live; wireframe and feature-point overlays; the \
                      face's FAP units are shown. Without STREAM the page shows the neutral \
                      face with its sliders. FACE is a VRML face file (.wrl, .wrl.gz), an OBJ \
                      with --fp, or `alma` / `bruno`.",
        after_help = "Examples:\n  fbakit view alma samples/speech.fap -o alma.html\n  \
                      fbakit view bruno -o bruno.html\n  \
                      fbakit view face.wrl.gz talk.fap -o talk.html --fps 30 --frames 0..300\n  \
                      fbakit view head.obj --fp head.fdp -o head.html"
    )]
    View(view::ViewArgs),
    /// Render a FAP stream played on a face as a video: .mp4 (with --audio), .gif or PNG frames.
    #[command(
        long_about = "Render a FAP stream played on a face as a video at the stream's frame \
                      rate (--fps to resample), the camera framed on the face's feature \
                      points. OUT ending in .mp4 gives H.264 (yuv420p, plays in browsers) \
                      through the ffmpeg program, with --audio muxed in as AAC: the video \
                      sets the length (longer audio is cut, shorter audio ends in silence). \
                      OUT ending in .gif gives an animated GIF; a directory gives one PNG \
                      per frame (frame_00000.png, ...). Frames are streamed: memory does \
                      not grow with the length. Nothing is left behind on failure. Exit \
                      codes: 0 ok, 2 bad usage or input, 1 other failures (including \
                      ffmpeg not installed).",
        after_help = "Examples:\n  fbakit render alma samples/speech.fap -o speech.mp4\n  \
                      fbakit speak \"Hello world\" -o hello.fap --wav hello.wav && \
                      fbakit render alma hello.fap --audio hello.wav -o hello.mp4\n  \
                      fbakit render bruno samples/speech.fap -o speech.gif --size 256x256 --fps 12.5\n  \
                      fbakit render alma samples/lowlevel.fap -o frames/"
    )]
    Render(render::RenderArgs),
    /// Say a text with espeak-ng: a FAP stream of blended visemes (25 fps) and the WAV audio.
    #[command(
        long_about = "Say TEXT with the espeak-ng speech synthesiser (its library \
                      libespeak-ng, Debian package espeak-ng): the phonemes and their timing \
                      come from the same synthesis as the audio, each phoneme becomes one of \
                      the standard's 14 visemes (specs/phoneme-visemes.csv), neighbouring \
                      visemes are blended with FAP 1 (viseme_select1/2 + blend), and the \
                      stream lasts as long as the audio (within half a frame). --mouth faps \
                      writes jaw and lip FAPs instead, for faces without viseme tables. Exit \
                      codes: 0 ok, 2 bad input (empty text, unknown voice), 1 other failures \
                      (including espeak-ng not installed).",
        after_help = "Examples:\n  fbakit speak \"Hello world\" -o hello.mp4            the real head says it, with sound\n  \
                      fbakit speak \"Hello world\" -o hello.html --face alma\n  \
                      fbakit speak \"Hello world\" -o hello.fap --wav hello.wav\n  \
                      fbakit render alma hello.fap --audio hello.wav -o hello.mp4\n  \
                      fbakit speak \"Guten Tag\" --voice de -o tag.fap --wav tag.wav\n  \
                      fbakit speak \"Hello\" --mouth faps -o hello-candide.fap --json"
    )]
    Speak(speak::SpeakArgs),
    /// Lip-sync a voice recording: its transcript aligned to it, a talking face out.
    #[command(
        long_about = "Animate a face from a voice recording and its transcript. The \
                      transcript is spoken by espeak-ng (library libespeak-ng, Debian package \
                      espeak-ng), which gives its phonemes in 100+ languages (--lang); the \
                      rendition is aligned to the recording by dynamic time warping of their \
                      MFCCs; for English recordings up to 2 minutes the phones are then placed \
                      by PocketSphinx forced alignment when it is installed (Debian packages \
                      pocketsphinx pocketsphinx-en-us; without it the warp's times are used). \
                      Silences relax the mouth, and the phones become FAP 1 visemes with \
                      blends (never skipping a lip closure, no shape shorter than a frame). \
                      The recording is read a chunk at a time. A transcript that fits poorly \
                      gives a warning with its confidence; one that does not fit at all is \
                      refused. Without a transcript (English only) the phones are recognised with \
                      PocketSphinx (Debian packages pocketsphinx pocketsphinx-en-us) and lip \
                      closures are found in the sound; rougher than with one. \
                      Exit codes: 0 ok, 2 bad usage or input (unreadable recording, silence, \
                      a transcript that cannot be aligned, espeak-ng or PocketSphinx not \
                      installed), 1 other failures.",
        after_help = "Examples:\n  fbakit lipsync voice.wav --text \"Hello world\" -o hello.mp4       the face says it, with the recording as sound\n  \
                      fbakit lipsync voice.wav --text-file voice.txt -o voice.fap --json\n  \
                      fbakit lipsync rede.wav --text \"Guten Tag\" --lang de -o rede.html --face alma\n  \
                      fbakit lipsync voice.wav --text-file voice.txt --face rig.glb --fp rig-fp.csv -o voice.csv"
    )]
    Lipsync(lipsync::LipsyncArgs),
    /// Read blendshape rigs (glTF morph targets, OBJ shape folders such as the ICT-FaceKit).
    #[command(
        subcommand,
        after_help = "Example:\n  fbakit rig info ../shared/data/ict-facekit"
    )]
    Rig(rig::RigCommand),
    /// Print a shell completion script (bash, zsh, fish, elvish, powershell) on stdout.
    #[command(
        after_help = "Examples:\n  fbakit completions bash > ~/.local/share/bash-completion/completions/fbakit\n  \
                      fbakit completions zsh > ~/.zfunc/_fbakit\n  \
                      fbakit completions fish > ~/.config/fish/completions/fbakit.fish"
    )]
    Completions(docs::CompletionsArgs),
    /// Write man pages: fbakit.1 and one page per subcommand (fbakit-play.1, ...).
    #[command(after_help = "Examples:\n  fbakit man -o man/\n  man -l man/fbakit-play.1")]
    Man(docs::ManArgs),
}

#[derive(Debug, clap::Args)]
pub struct SpecArgs {
    /// Which table: `faps` or `feature-points`.
    #[arg(value_parser = ["faps", "feature-points"], default_value = "faps")]
    pub table: String,
    /// Print JSON instead of a text table.
    #[arg(long)]
    pub json: bool,
}

/// Runs a parsed command line and maps the outcome to an exit code; `json` makes an error
/// a JSON object (see [`print_error`]).
pub fn run(cli: Cli, json: bool) -> ExitCode {
    let result = match cli.command {
        Command::Spec(args) => spec(args),
        Command::Fapu(args) => fapu::run(args),
        Command::Fap(cmd) => fap::run(cmd),
        Command::Fp(cmd) => fp::run(cmd),
        Command::Play(args) => play::run(args),
        Command::Face(cmd) => face::run(cmd),
        Command::Candide(args) => candide::run(args),
        Command::Sample(args) => candide::sample(args),
        Command::Clone(args) => clone::run(args),
        Command::Eval(cmd) => clone::run_eval(cmd),
        Command::Grid(args) => show::grid(args),
        Command::Demo(args) => show::demo(args),
        Command::View(args) => view::run(args),
        Command::Render(args) => render::run(args),
        Command::Speak(args) => speak::run(args),
        Command::Lipsync(args) => lipsync::run(args),
        Command::Rig(cmd) => rig::run(cmd),
        Command::Completions(args) => docs::completions(args),
        Command::Man(args) => docs::man(args),
    };
    match result {
        Ok(code) => ExitCode::from(code),
        Err(e) => report_error(&e, json),
    }
}

/// Whether the command line asks for JSON output (`--json` before any `--`), so errors,
/// including clap's usage errors that come before a command is parsed, are JSON too.
pub fn wants_json(args: &[std::ffi::OsString]) -> bool {
    args.iter()
        .skip(1)
        .take_while(|a| a.as_os_str() != "--")
        .any(|a| a.as_os_str() == "--json")
}

/// Prints an error to stderr (one line of text, or one JSON object under `--json`) and
/// returns `code`.
pub fn print_error(message: &str, code: u8, json: bool) -> ExitCode {
    // Messages quote file content and names; the same escaped text in both forms.
    let message = fbakit::error::escape_control(message);
    if json {
        let kind = if code == EXIT_BAD_INPUT {
            "bad-input"
        } else {
            "failure"
        };
        let value = serde_json::json!({
            "error": { "message": message, "exit_code": code, "kind": kind }
        });
        eprintln!("{value}");
    } else {
        eprintln!("error: {message}");
    }
    ExitCode::from(code)
}

/// Prints a library error to stderr and picks its exit code.
pub fn report_error(e: &fbakit::error::Error, json: bool) -> ExitCode {
    let code = if e.is_input_error() {
        EXIT_BAD_INPUT
    } else {
        EXIT_FAILURE
    };
    print_error(&e.to_string(), code, json)
}

/// Prints warnings to stderr, each once and with one `warning:` prefix (library warnings
/// sometimes carry their own).
pub fn print_warnings<S: WarningText>(warnings: &[S]) {
    let mut seen = std::collections::HashSet::new();
    for w in warnings {
        let w = w.warning_text();
        let w = w.trim();
        let w = w.strip_prefix("warning:").map_or(w, str::trim_start);
        if seen.insert(w.to_string()) {
            eprintln!("warning: {}", fbakit::error::escape_control(w));
        }
    }
}

/// Something [`print_warnings`] can print: plain text or a [`Diagnostic`] (printed with its
/// location, the `warning:` prefix once).
pub trait WarningText {
    /// The text after the `warning:` prefix.
    fn warning_text(&self) -> std::borrow::Cow<'_, str>;
}

impl WarningText for String {
    fn warning_text(&self) -> std::borrow::Cow<'_, str> {
        self.as_str().into()
    }
}

impl WarningText for &str {
    fn warning_text(&self) -> std::borrow::Cow<'_, str> {
        (*self).into()
    }
}

impl WarningText for Diagnostic {
    fn warning_text(&self) -> std::borrow::Cow<'_, str> {
        self.located_message().into()
    }
}

/// Prints text that quotes file content (names, versions, findings) on stdout, its control
/// characters escaped (see [`fbakit::error::escape_control`]).
pub fn print_text(text: &str) {
    print!("{}", fbakit::error::escape_control(text));
}

/// Prints any serialisable value as pretty JSON on stdout.
pub fn print_json<T: serde::Serialize>(value: &T) -> fbakit::error::Result<()> {
    let text = serde_json::to_string_pretty(value)
        .map_err(|e| fbakit::error::EncodeError::new("JSON", e))?;
    println!("{text}");
    Ok(())
}

fn spec(args: SpecArgs) -> fbakit::error::Result<u8> {
    use fbakit::spec::{FapId, FeaturePointId};
    if args.table == "faps" {
        let rows: Vec<_> = FapId::all().map(|id| id.info()).collect();
        if args.json {
            print_json(&rows)?;
        } else {
            println!(
                "{:>3}  {:<22} {:<6} {:<3} {:<15} fp",
                "fap", "name", "fapu", "dir", "positive"
            );
            for r in rows {
                let fps: Vec<String> = r.feature_points.iter().map(|p| p.to_string()).collect();
                println!(
                    "{:>3}  {:<22} {:<6} {:<3} {:<15} {}",
                    r.number,
                    r.name,
                    r.fapu.map_or("-", |f| f.abbreviation()),
                    match r.directionality {
                        Some(fbakit::spec::Directionality::Unidirectional) => "U",
                        Some(fbakit::spec::Directionality::Bidirectional) => "B",
                        None => "-",
                    },
                    r.positive_motion.map_or("-", |m| m.word()),
                    fps.join(" ")
                );
            }
        }
    } else {
        let rows: Vec<_> = FeaturePointId::all().map(|id| id.info()).collect();
        if args.json {
            print_json(&rows)?;
        } else {
            for r in rows {
                println!("{:<6} {:?}  {}", r.id.to_string(), r.side, r.description);
            }
        }
    }
    Ok(EXIT_OK)
}
