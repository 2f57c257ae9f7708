//! `primo scale`: serve the simulated scale over MT-SICS, read a scale
//! (MT-SICS, or primo's load-cell scale over the wire protocol).

use std::io::BufRead;
use std::time::Duration;

use clap::{Args, Subcommand, ValueEnum};

use primo_learn::coprocessor::{Image, Qemu};
use primo_learn::pour::weigh::{Density, PrimoScale, ScaleSpec};
use primo_mtsics::{Client, ClientConfig, Fixed, Unit, quote};
use primo_protocol::scale::{
    CalibrationPoint, Reading, ScaleRequest, Unit as ScaleUnit, WeighMode,
};
use primo_sim::load_cell::{LoadCellModel, LoadCellServer};
use primo_sim::scale::ScaleModel;
use primo_sim::scale_device::{Control, Device, DeviceConfig, LoadHandle, PtyServer};

use crate::error::CliError;
use crate::output::say;
use crate::terminal::in_background;

/// `primo scale` subcommands.
#[derive(Debug, Subcommand)]
pub enum ScaleCommand {
    /// Serve the simulated scale over MT-SICS on a new pseudo-terminal.
    ///
    /// Prints the terminal's path on the first line, then reads operator
    /// commands on stdin, one a line, and answers each with one line
    /// (`ok ...` or `error: ...`): `load <grams>` puts a load on the pan,
    /// `garbage <text>` sends a raw line (`\xNN`, `\r`, `\n`, `\t`, `\\`
    /// escapes), `silent <seconds>` answers nothing for a while (0 ends
    /// it), `power-on` sends the power-on line. Serves on after stdin closes,
    /// until the process is killed.
    Serve(ServeArgs),
    /// Read one stable weight from a scale and print it: an MT-SICS scale,
    /// or primo's load-cell scale (`postcard:PORT`, or its firmware in
    /// QEMU: `qemu` on a simulated load cell holding --load, `qemu:PATH`
    /// on a load cell's line).
    Read(ReadArgs),
    /// Set the scale's zero at the load on the pan now (MT-SICS `Z`, or
    /// primo's scale), waiting for it to be stable.
    Zero(SetArgs),
    /// Tare the load on the pan now (MT-SICS `T`, or primo's scale, which
    /// keeps it in its settings page; an MT-SICS balance forgets it at the
    /// `@` primo sends when it next connects).
    Tare(SetArgs),
    /// Take a calibration point on primo's scale at the load on the pan
    /// now: `--low GRAMS` first (usually the empty pan, 0), then `--high
    /// GRAMS` (a reference weight), which completes it and is kept in the
    /// scale's settings page. MT-SICS balances calibrate themselves.
    Calibrate(CalibrateArgs),
}

/// `primo scale zero|tare` options.
#[derive(Debug, Args)]
pub struct SetArgs {
    #[command(flatten)]
    scale: ScaleArgs,
}

/// `primo scale calibrate` options.
#[derive(Debug, Args)]
pub struct CalibrateArgs {
    #[command(flatten)]
    scale: ScaleArgs,
    /// The lower calibration mass on the pan now, g.
    #[arg(
        long,
        value_name = "GRAMS",
        conflicts_with = "high",
        required_unless_present = "high",
        allow_hyphen_values = true
    )]
    low: Option<f32>,
    /// The upper calibration mass on the pan now, g.
    #[arg(long, value_name = "GRAMS", allow_hyphen_values = true)]
    high: Option<f32>,
}

/// `primo scale serve` options.
#[derive(Debug, Args)]
pub struct ServeArgs {
    /// Load on the pan from the start (already settled), g.
    #[command(flatten)]
    load: LoadArg,
    /// Seed of the scale's noise.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// How long `S`, `Z` and `T` wait for a stable reading before they
    /// answer `I`, s.
    #[arg(long, value_name = "SECONDS", default_value_t = 8.0)]
    stable_timeout: f64,
}

/// A load on a simulated pan.
#[derive(Debug, Args)]
pub struct LoadArg {
    /// The load on the pan, g.
    #[arg(
        long,
        value_name = "GRAMS",
        default_value_t = 0.0,
        allow_hyphen_values = true
    )]
    load: f64,
}

impl LoadArg {
    /// The load as a shared handle, if it is a weight.
    fn handle(&self) -> Result<LoadHandle, CliError> {
        if !self.load.is_finite() {
            return Err(CliError::input(format!(
                "--load: {} is not a weight in grams",
                self.load
            )));
        }
        Ok(LoadHandle::new(self.load))
    }
}

/// How to reach a scale.
#[derive(Debug, Args)]
pub struct ScaleArgs {
    /// The scale: an MT-SICS scale's serial port (e.g. /dev/ttyUSB0, or
    /// the path `primo scale serve` printed); `postcard:PORT`, primo's
    /// scale; `qemu:LOAD_CELL`, its firmware booted in QEMU on a load
    /// cell's line (`primo robot sim-krc --load-cell`); `qemu`, the same on
    /// a simulated load cell holding --load.
    #[arg(long, value_name = "PATH|postcard:PORT|qemu[:LOAD_CELL]")]
    port: String,
    /// With `--port qemu`: the load on the simulated cell.
    #[command(flatten)]
    load: LoadArg,
    /// Baud rate (8N1, no handshake).
    #[arg(long, default_value_t = 9600)]
    baud: u32,
    /// How long the scale may stay silent (noise is no answer) before
    /// primo gives up, the re-sends included, s.
    #[arg(long, value_name = "SECONDS", default_value_t = 10.0)]
    timeout: f64,
    /// Re-sends of a command within --timeout while nothing answers.
    #[arg(long, default_value_t = 2)]
    retries: u32,
    /// How long to keep asking while the scale answers that it is not
    /// stable yet (`S I`), s.
    #[arg(long, value_name = "SECONDS", default_value_t = 60.0)]
    settle: f64,
}

/// `primo scale read` options.
#[derive(Debug, Args)]
pub struct ReadArgs {
    #[command(flatten)]
    scale: ScaleArgs,
    /// primo's scale: print this many readings as it streams them (every
    /// 8th sample, stable or not), then how fast they came.
    #[arg(long, value_name = "N")]
    stream: Option<usize>,
    /// Unit to print; `ml` converts through --density.
    #[arg(long, value_enum, default_value_t = OutputUnit::G)]
    unit: OutputUnit,
    /// Density of the liquid for `--unit ml`, g/ml (water: 0.998).
    #[arg(long, value_name = "G_PER_ML", default_value_t = Density::WATER.g_per_ml())]
    density: f64,
}

/// What `primo scale read` prints in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
enum OutputUnit {
    G,
    Mg,
    Kg,
    Ml,
}

/// How long the `--load` has stood on the pan when serving starts, s.
const SETTLED: f64 = 30.0;

/// Runs a `primo scale` subcommand.
pub fn run(command: ScaleCommand) -> Result<(), CliError> {
    match command {
        ScaleCommand::Serve(args) => serve(&args),
        ScaleCommand::Read(args) => read(&args),
        ScaleCommand::Zero(args) => set(&args.scale, Setting::Zero),
        ScaleCommand::Tare(args) => set(&args.scale, Setting::Tare),
        ScaleCommand::Calibrate(args) => {
            let point = match (args.low, args.high) {
                (Some(grams), _) => CalibrationPoint::Low { grams },
                (None, Some(grams)) => CalibrationPoint::High { grams },
                (None, None) => return Err(CliError::input("give --low GRAMS or --high GRAMS")),
            };
            set(&args.scale, Setting::Calibrate(point))
        }
    }
}

fn serve(args: &ServeArgs) -> Result<(), CliError> {
    let load = args.load.handle()?;
    let model = ScaleModel::default();
    let config = DeviceConfig {
        stable_timeout: args.stable_timeout,
        ..DeviceConfig::for_model(&model)
    };
    let mut device = Device::new(model, args.seed, load.clone(), config)
        .map_err(|e| CliError::input(format!("--stable-timeout: {e}")))?;
    device.advance(SETTLED);
    let server = PtyServer::start(device)
        .map_err(|e| CliError::other(format!("cannot serve on a pseudo-terminal: {e}")))?;
    say(server.path())?;
    // Operator commands while stdin is open (not read from the background
    // of a terminal, which would stop the process); the scale is served
    // on until the process is killed, as `primo robot sim-krc` serves.
    if !in_background() {
        for (i, line) in std::io::stdin().lock().split(b'\n').enumerate() {
            let line = line.map_err(|e| CliError::other(format!("stdin: {e}")))?;
            let line = line.strip_suffix(b"\r").unwrap_or(&line);
            if line.trim_ascii().is_empty() {
                continue;
            }
            let reply = match operate(&server, &load, line) {
                Ok(done) => format!("ok {done}"),
                Err(e) => format!("error: stdin line {}: {e}", i + 1),
            };
            say(&reply)?;
        }
    }
    server
        .serve_on()
        .map_err(|e| CliError::other(format!("serving failed: {e}")))
}

/// One operator command; what was done.
fn operate(server: &PtyServer, load: &LoadHandle, line: &[u8]) -> Result<String, String> {
    let line = line.trim_ascii_start();
    let split = line
        .iter()
        .position(|b| b.is_ascii_whitespace())
        .unwrap_or(line.len());
    let (word, rest) = line.split_at(split);
    let rest = rest.trim_ascii();
    let number = |what: &str| -> Result<f64, String> {
        std::str::from_utf8(rest)
            .ok()
            .and_then(|t| t.parse::<f64>().ok())
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("{what}: `{}` is not a number", quote(rest)))
    };
    let control = |c: Control| server.control(c).map_err(|e| e.to_string());
    match word {
        b"load" => {
            let grams = number("load <grams>")?;
            load.set(grams);
            Ok(format!("load {grams} g"))
        }
        b"garbage" => {
            let bytes = unescape(rest)?;
            control(Control::Garbage(bytes.clone()))?;
            Ok(format!("garbage {}", quote(&bytes)))
        }
        b"silent" => {
            let seconds = number("silent <seconds>")?;
            let d = Duration::try_from_secs_f64(seconds)
                .map_err(|_| format!("silent <seconds>: {seconds} is not a duration"))?;
            control(Control::Silent(d))?;
            Ok(format!("silent {seconds} s"))
        }
        b"power-on" if rest.is_empty() => {
            control(Control::PowerOn)?;
            Ok("power-on".into())
        }
        _ => Err(format!(
            "`{}`: expected `load <grams>`, `garbage <text>`, `silent <seconds>` or `power-on`",
            quote(line)
        )),
    }
}

/// `text` with `\xNN`, `\r`, `\n`, `\t` and `\\` escapes resolved.
fn unescape(text: &[u8]) -> Result<Vec<u8>, String> {
    let mut out = Vec::with_capacity(text.len());
    let mut bytes = text.iter().copied();
    while let Some(b) = bytes.next() {
        if b != b'\\' {
            out.push(b);
            continue;
        }
        let byte = match bytes.next() {
            Some(b'\\') => b'\\',
            Some(b'r') => b'\r',
            Some(b'n') => b'\n',
            Some(b't') => b'\t',
            Some(b'x') => {
                let hex = [bytes.next(), bytes.next()];
                let digits: Option<Vec<u8>> = hex.into_iter().collect();
                digits
                    .and_then(|d| {
                        std::str::from_utf8(&d)
                            .ok()
                            .and_then(|h| u8::from_str_radix(h, 16).ok())
                    })
                    .ok_or("garbage: `\\x` needs two hex digits")?
            }
            _ => return Err("garbage: unknown escape (use \\xNN, \\r, \\n, \\t or \\\\)".into()),
        };
        out.push(byte);
    }
    Ok(out)
}

/// Reads primo's scale: one stable weight in --unit, or --stream readings.
fn primo_read(mut scale: PrimoScale, args: &ReadArgs, density: Density) -> Result<(), CliError> {
    let Some(count) = args.stream else {
        let unit = match args.unit {
            OutputUnit::Mg => ScaleUnit::Mg,
            OutputUnit::Kg => ScaleUnit::Kg,
            OutputUnit::G | OutputUnit::Ml => ScaleUnit::G,
        };
        let r = scale.weigh(WeighMode::Stable, unit)?;
        return say(&shown(&r, args.unit, density));
    };
    let start = std::time::Instant::now();
    let readings = scale.stream(8, count)?;
    let took = start.elapsed().as_secs_f64();
    for r in &readings {
        match r {
            Ok(r) if r.stable => say(&shown(r, args.unit, density))?,
            Ok(r) => say(&format!("{} (moving)", shown(r, args.unit, density)))?,
            Err(fault) => say(&fault.to_string())?,
        }
    }
    say(&format!(
        "{count} readings in {took:.2} s: {:.1} samples/s",
        (8 * count) as f64 / took
    ))
}

/// A reading as the scale shows it, or as a volume.
fn shown(r: &Reading, unit: OutputUnit, density: Density) -> String {
    let decimals = usize::try_from(-i32::from(r.exponent)).unwrap_or(0);
    match unit {
        OutputUnit::Ml => format!("{} ml", Fixed(density.millilitres(r.grams()), decimals)),
        _ => format!("{} {}", Fixed(r.value(), decimals), r.unit.symbol()),
    }
}

/// A time limit in seconds: more than 0 and at most a day.
fn limit(flag: &str, seconds: f64) -> Result<Duration, CliError> {
    Duration::try_from_secs_f64(seconds)
        .ok()
        .filter(|t| !t.is_zero() && t.as_secs_f64() <= 86_400.0)
        .ok_or_else(|| {
            CliError::input(format!(
                "{flag}: {seconds} s must be more than 0 s and at most a day (86400 s)"
            ))
        })
}

/// A scale reached: primo's (with the simulated load cell it may stand
/// on) or an MT-SICS balance.
enum Opened {
    Primo(PrimoScale, Option<LoadCellServer>),
    MtSics(Client),
}

fn open(args: &ScaleArgs) -> Result<Opened, CliError> {
    let timeout = limit("--timeout", args.timeout)?;
    let settle = limit("--settle", args.settle)?;
    if args.port == "qemu" {
        let cell = LoadCellServer::start(LoadCellModel::default(), 1, args.load.handle()?)
            .map_err(|e| CliError::other(format!("cannot serve the load cell: {e}")))?;
        let scale = PrimoScale::boot(&Qemu::find(Image::Scale)?, cell.path(), settle)?;
        return Ok(Opened::Primo(scale, Some(cell)));
    }
    let spec = ScaleSpec::parse(&args.port).map_err(|e| match e {
        primo_learn::Error::Setting { value, why, .. } => CliError::input(format!(
            "--port {value}: {why}{}",
            crate::error::load_cell_hint(&value)
        )),
        e => e.into(),
    })?;
    Ok(match spec {
        ScaleSpec::Postcard(port) => {
            Opened::Primo(PrimoScale::open(&port, settle).map_err(on_port)?, None)
        }
        ScaleSpec::Qemu(cell) => Opened::Primo(
            PrimoScale::boot(&Qemu::find(Image::Scale)?, &cell, settle)?,
            None,
        ),
        ScaleSpec::MtSics(port) => {
            let config = ClientConfig {
                baud: args.baud,
                timeout,
                retries: args.retries,
                settle,
                ..ClientConfig::default()
            };
            Opened::MtSics(Client::open(&port, config).map_err(|e| on_port(e.into()))?)
        }
    })
}

/// A scale's error, a port that would not open named by its flag here.
fn on_port(e: primo_learn::Error) -> CliError {
    match e {
        primo_learn::Error::Open { path, fault, .. } => {
            CliError::opening(format!("--port {}: {fault}", path.display()), &fault)
        }
        e => e.into(),
    }
}

fn read(args: &ReadArgs) -> Result<(), CliError> {
    let density =
        Density::new(args.density).map_err(|e| CliError::input(format!("--density: {e}")))?;
    let mut client = match open(&args.scale)? {
        Opened::Primo(scale, _cell) => return primo_read(scale, args, density),
        Opened::MtSics(client) => client,
    };
    if args.stream.is_some() {
        return Err(CliError::input(
            "--stream: streaming is primo's scale's (--port postcard:PORT or qemu)",
        ));
    }
    let weight = client.stable()?;
    let text = match args.unit {
        OutputUnit::G => weight.to(Unit::G).to_string(),
        OutputUnit::Mg => weight.to(Unit::Mg).to_string(),
        OutputUnit::Kg => weight.to(Unit::Kg).to_string(),
        OutputUnit::Ml => format!(
            "{} ml",
            Fixed(
                density.millilitres(weight.grams()),
                usize::from(weight.to(Unit::G).decimals)
            )
        ),
    };
    say(&text)
}

/// What `primo scale zero|tare|calibrate` sets.
enum Setting {
    Zero,
    Tare,
    Calibrate(CalibrationPoint),
}

fn set(args: &ScaleArgs, setting: Setting) -> Result<(), CliError> {
    if let Setting::Calibrate(CalibrationPoint::Low { grams } | CalibrationPoint::High { grams }) =
        setting
        && !grams.is_finite()
    {
        return Err(CliError::input(format!(
            "--low/--high: {grams} is not a mass in grams"
        )));
    }
    match (open(args)?, setting) {
        (Opened::Primo(mut scale, _cell), setting) => {
            let (request, done) = match setting {
                Setting::Zero => (ScaleRequest::Zero, "zeroed".to_string()),
                Setting::Tare => (ScaleRequest::Tare, "tared".to_string()),
                Setting::Calibrate(point) => (
                    ScaleRequest::Calibrate(point),
                    match point {
                        CalibrationPoint::Low { grams } => {
                            format!("low calibration point {grams} g taken; now --high")
                        }
                        CalibrationPoint::High { grams } => {
                            format!("high calibration point {grams} g taken: calibrated")
                        }
                    },
                ),
            };
            scale.set(&request)?;
            say(&done)
        }
        (Opened::MtSics(mut client), Setting::Zero) => {
            client.zero()?;
            say("zeroed")
        }
        (Opened::MtSics(mut client), Setting::Tare) => {
            let tare = client.tare()?;
            say(&format!("tared {tare}"))?;
            // Every connection begins with the reset `@`, which clears it.
            eprintln!(
                "primo scale tare: warning: an MT-SICS balance keeps this tare only until \
                 primo next connects (each connection begins with the reset `@`): the next \
                 `primo scale read` weighs the gross load again"
            );
            Ok(())
        }
        (Opened::MtSics(_), Setting::Calibrate(_)) => Err(CliError::input(
            "calibrate: an MT-SICS balance calibrates itself (its own menu or `C` \
             commands); this is for primo's scale (--port postcard:PORT)",
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn garbage_escapes() {
        assert_eq!(
            unescape(br"a\x41\xff\r\n\t\\b").unwrap(),
            b"aA\xff\r\n\t\\b"
        );
        assert!(unescape(br"\x4").is_err());
        assert!(unescape(br"\xzz").is_err());
        assert!(unescape(br"\q").is_err());
        assert!(unescape(b"\\").is_err());
    }
}
