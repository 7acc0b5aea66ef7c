//! Fault injection for the simulated grabber, as `vss sim --faults` takes it:
//! `drop=RATE,corrupt=RATE,stall=DURATION,slow-freeze=DURATION,unplug-after=BYTES,reset,garbage=BYTES`.
//! Faults act on the bytes the device sends (drops, corruption, the unplug
//! count) and on its behaviour (a stall, a reset in the middle of a frame).

use std::time::Duration;

use crate::llv::rng::SplitMix64;

/// The faults asked for; the default is a clean line.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Faults {
    /// Probability that a byte the device sends is lost.
    pub drop: f64,
    /// Probability that a byte the device sends is changed.
    pub corrupt: f64,
    /// The device goes silent this long, once, at the first READ past the
    /// start of a frame.
    pub stall: Option<Duration>,
    /// The first FREEZE takes this long before it digitises (a slow
    /// digitiser, or a busy machine running the simulator).
    pub slow_freeze: Option<Duration>,
    /// The device vanishes (its pseudo-terminal closes) after sending this
    /// many bytes.
    pub unplug_after: Option<u64>,
    /// The device resets (forgets its frame and camera) at the first READ
    /// past the start of a frame.
    pub reset: bool,
    /// Random bytes the device sends as soon as it starts.
    pub garbage: usize,
    /// Seed of the fault dice (default: the scene seed).
    pub seed: Option<u64>,
}

/// A `--faults` string that does not parse.
#[derive(Debug, thiserror::Error)]
#[error(
    "bad fault `{item}`: {why} (expected drop=RATE,corrupt=RATE,stall=2s,slow-freeze=2s,unplug-after=BYTES,reset,garbage=BYTES,seed=N)"
)]
pub struct FaultsError {
    pub item: String,
    pub why: String,
}

fn parse_duration(s: &str) -> Option<Duration> {
    let (num, unit) = match s.find(|c: char| c.is_ascii_alphabetic()) {
        Some(i) => s.split_at(i),
        None => (s, "s"),
    };
    let v: f64 = num.parse().ok()?;
    if !v.is_finite() || v < 0.0 {
        return None;
    }
    let secs = match unit {
        "s" => v,
        "ms" => v / 1000.0,
        "m" | "min" => v * 60.0,
        _ => return None,
    };
    Duration::try_from_secs_f64(secs).ok()
}

impl Faults {
    /// Whether no fault is asked for (the seed alone is no fault).
    pub fn is_clean(&self) -> bool {
        Faults {
            seed: None,
            ..self.clone()
        } == Faults::default()
    }

    pub fn parse(spec: &str) -> Result<Faults, FaultsError> {
        let mut f = Faults::default();
        for item in spec.split(',').map(str::trim).filter(|s| !s.is_empty()) {
            let err = |why: &str| FaultsError {
                item: item.to_string(),
                why: why.to_string(),
            };
            let (key, value) = item.split_once('=').unwrap_or((item, ""));
            let rate = || -> Result<f64, FaultsError> {
                let r: f64 = value.parse().map_err(|_| err("not a number"))?;
                if (0.0..=1.0).contains(&r) {
                    Ok(r)
                } else {
                    Err(err("a rate is between 0 and 1"))
                }
            };
            match key {
                "drop" => f.drop = rate()?,
                "corrupt" => f.corrupt = rate()?,
                "stall" => {
                    f.stall = Some(
                        parse_duration(value)
                            .ok_or_else(|| err("not a duration like 2s or 500ms"))?,
                    )
                }
                "slow-freeze" => {
                    f.slow_freeze = Some(
                        parse_duration(value)
                            .ok_or_else(|| err("not a duration like 2s or 500ms"))?,
                    )
                }
                "unplug-after" => {
                    f.unplug_after = Some(value.parse().map_err(|_| err("not a byte count"))?)
                }
                "reset" if value.is_empty() => f.reset = true,
                "garbage" => f.garbage = value.parse().map_err(|_| err("not a byte count"))?,
                "seed" => f.seed = Some(value.parse().map_err(|_| err("not a number"))?),
                _ => return Err(err("unknown fault")),
            }
        }
        Ok(f)
    }

    /// A short summary for people.
    pub fn summary(&self) -> String {
        let mut parts = Vec::new();
        if self.drop > 0.0 {
            parts.push(format!("drop={}", self.drop));
        }
        if self.corrupt > 0.0 {
            parts.push(format!("corrupt={}", self.corrupt));
        }
        if let Some(d) = self.stall {
            parts.push(format!("stall={}ms", d.as_millis()));
        }
        if let Some(d) = self.slow_freeze {
            parts.push(format!("slow-freeze={}ms", d.as_millis()));
        }
        if let Some(n) = self.unplug_after {
            parts.push(format!("unplug-after={n}"));
        }
        if self.reset {
            parts.push("reset".into());
        }
        if self.garbage > 0 {
            parts.push(format!("garbage={}", self.garbage));
        }
        if parts.is_empty() {
            "no faults".into()
        } else {
            parts.join(",")
        }
    }
}

/// The faults at work on one device: the dice and what has fired.
pub(crate) struct FaultState {
    pub faults: Faults,
    rng: SplitMix64,
    pub sent: u64,
    pub stall_done: bool,
    pub slow_freeze_done: bool,
    pub reset_done: bool,
}

/// What became of bytes on their way out.
pub(crate) enum Outgoing {
    /// Send these (possibly damaged) bytes.
    Send(Vec<u8>),
    /// Send these, then vanish.
    SendThenUnplug(Vec<u8>),
}

impl FaultState {
    pub fn new(faults: Faults, seed: u64) -> FaultState {
        let seed = faults.seed.unwrap_or(seed) ^ 0xFA17_5EED;
        FaultState {
            faults,
            rng: SplitMix64::new(seed),
            sent: 0,
            stall_done: false,
            slow_freeze_done: false,
            reset_done: false,
        }
    }

    pub fn garbage(&mut self) -> Vec<u8> {
        (0..self.faults.garbage)
            .map(|_| (self.rng.next_u64() & 0xff) as u8)
            .collect()
    }

    /// Applies drops, corruption and the unplug count to outgoing bytes.
    pub fn outgoing(&mut self, bytes: &[u8]) -> Outgoing {
        let (drop, corrupt) = (self.faults.drop, self.faults.corrupt);
        let mut out = Vec::with_capacity(bytes.len());
        let limit = self.faults.unplug_after;
        for &b in bytes {
            if limit.is_some_and(|n| self.sent >= n) {
                return Outgoing::SendThenUnplug(out);
            }
            self.sent += 1;
            if drop > 0.0 && self.rng.uniform() < drop {
                continue;
            }
            if corrupt > 0.0 && self.rng.uniform() < corrupt {
                let flip = (self.rng.next_u64() % 255) as u8 + 1;
                out.push(b ^ flip);
                continue;
            }
            out.push(b);
        }
        if limit.is_some_and(|n| self.sent >= n) {
            return Outgoing::SendThenUnplug(out);
        }
        Outgoing::Send(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_the_documented_spec() {
        let f = Faults::parse(
            "drop=1e-4,corrupt=1e-4,stall=2s,slow-freeze=1s,unplug-after=100000,reset,garbage=50",
        );
        let f = f.ok();
        assert_eq!(
            f,
            Some(Faults {
                drop: 1e-4,
                corrupt: 1e-4,
                stall: Some(Duration::from_secs(2)),
                slow_freeze: Some(Duration::from_secs(1)),
                unplug_after: Some(100_000),
                reset: true,
                garbage: 50,
                seed: None,
            })
        );
        assert!(Faults::parse("").is_ok_and(|f| f.is_clean()));
        assert_eq!(
            Faults::parse("stall=250ms").ok().and_then(|f| f.stall),
            Some(Duration::from_millis(250))
        );
        for bad in [
            "drop=2",
            "drop=x",
            "stall=soon",
            "unplug-after=-1",
            "explode",
            "reset=1",
        ] {
            assert!(Faults::parse(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn rates_hit_roughly_as_asked_and_unplug_cuts_exactly() {
        let mut s = FaultState::new(Faults::parse("corrupt=0.01").unwrap_or_default(), 7);
        let data = vec![0u8; 100_000];
        let Outgoing::Send(out) = s.outgoing(&data) else {
            panic!("no unplug asked")
        };
        let changed = out.iter().filter(|&&b| b != 0).count();
        assert!((800..1200).contains(&changed), "{changed}");

        let mut s = FaultState::new(Faults::parse("unplug-after=10").unwrap_or_default(), 7);
        assert!(matches!(s.outgoing(&[1; 4]), Outgoing::Send(v) if v.len() == 4));
        assert!(matches!(s.outgoing(&[1; 20]), Outgoing::SendThenUnplug(v) if v.len() == 6));
    }
}
