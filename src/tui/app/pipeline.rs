//! The Pipeline screen's state and keys: the parameter panel (choose,
//! step, type a value; every change logged and re-run off the UI thread),
//! the stage view shown (one, or all side by side), which image the grey
//! view shows, and saving the outputs on screen.

use super::{Ctx, Modal, PreviewNav, PromptPurpose};
use crate::llv::params::{Kind, PARAMS, ParamSpec, fmt_value};
use crate::tui::event::Cmd;
use crate::tui::keymap::PipelineAction;

/// The stage views, in Tab order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StageView {
    Grey,
    Corrected,
    EdgesH,
    EdgesV,
    LinesRaw,
    Lines,
    Overlay,
}

impl StageView {
    pub const ALL: [StageView; 7] = [
        StageView::Grey,
        StageView::Corrected,
        StageView::EdgesH,
        StageView::EdgesV,
        StageView::LinesRaw,
        StageView::Lines,
        StageView::Overlay,
    ];
    pub fn title(self) -> &'static str {
        match self {
            StageView::Grey => "grey",
            StageView::Corrected => "corrected",
            StageView::EdgesH => "edges H",
            StageView::EdgesV => "edges V",
            StageView::LinesRaw => "raw lines",
            StageView::Lines => "connected lines",
            StageView::Overlay => "lines over grey",
        }
    }
    fn index(self) -> usize {
        Self::ALL.iter().position(|&v| v == self).unwrap_or(0)
    }
}

/// What the grey views show.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GreySource {
    /// The image of the `i`-th lighting (profile order; the ambient one too).
    Lighting(usize),
    /// The combined edge response `sqrt(H² + V²)` of every lighting.
    Combined,
}

impl Default for GreySource {
    fn default() -> Self {
        GreySource::Lighting(0)
    }
}

/// The Pipeline screen's own state.
#[derive(Clone, Debug)]
pub struct PipelineScreen {
    /// Index into [`PARAMS`].
    pub param: usize,
    pub view: StageView,
    pub side_by_side: bool,
    pub grey: GreySource,
    pub nav: PreviewNav,
}

impl Default for PipelineScreen {
    fn default() -> Self {
        PipelineScreen {
            param: 0,
            view: StageView::Overlay,
            side_by_side: false,
            grey: GreySource::default(),
            nav: PreviewNav::default(),
        }
    }
}

impl PipelineScreen {
    pub fn param_spec(&self) -> &'static ParamSpec {
        PARAMS.get(self.param).unwrap_or(&PARAMS[0])
    }

    pub fn update(&mut self, a: PipelineAction, ctx: &mut Ctx) -> Vec<Cmd> {
        let n = StageView::ALL.len();
        match a {
            PipelineAction::ParamPrev => self.param = self.param.saturating_sub(1),
            PipelineAction::ParamNext => self.param = (self.param + 1).min(PARAMS.len() - 1),
            PipelineAction::Inc => return self.step(ctx, 1.0),
            PipelineAction::Dec => return self.step(ctx, -1.0),
            PipelineAction::Inc10 => return self.step(ctx, 10.0),
            PipelineAction::Dec10 => return self.step(ctx, -10.0),
            PipelineAction::Type => {
                let sp = self.param_spec();
                let now = ctx
                    .tracker
                    .params
                    .get(sp.key)
                    .map(fmt_value)
                    .unwrap_or_default();
                let rule = format!("{} {} (now {now})", sp.range_text(), sp.unit);
                ctx.chrome.modal = Some(
                    Modal::prompt(
                        format!("{} =", sp.key),
                        rule.trim_end().to_string(),
                        now,
                        24,
                        PromptPurpose::ParamValue(sp.key),
                    )
                    .selected(),
                );
            }
            PipelineAction::Save => return ctx.save_outputs(false).unwrap_or_default(),
            PipelineAction::ResetParam => return ctx.reset_params(Some(self.param_spec().key)),
            PipelineAction::ResetAll => return ctx.reset_params(None),
            PipelineAction::ViewNext => self.view = StageView::ALL[(self.view.index() + 1) % n],
            PipelineAction::ViewPrev => {
                self.view = StageView::ALL[(self.view.index() + n - 1) % n];
            }
            PipelineAction::SideBySide => self.side_by_side = !self.side_by_side,
            PipelineAction::GreySource => {
                let letters = ctx.cell.letters.len();
                self.grey = match self.grey {
                    GreySource::Lighting(i) if i + 1 < letters => GreySource::Lighting(i + 1),
                    GreySource::Lighting(_) => GreySource::Combined,
                    GreySource::Combined => GreySource::Lighting(0),
                };
                let what = self.grey_name(ctx.cell);
                ctx.info(format!("grey view: {what}"));
            }
        }
        Vec::new()
    }

    /// The grey source in words: `lighting b`, `ambient (e)`, `combined response`.
    pub fn grey_name(&self, cell: &super::CellState) -> String {
        match self.grey {
            GreySource::Combined => "combined response".into(),
            GreySource::Lighting(i) => match cell.letters.get(i) {
                Some(&l) if Some(l) == cell.ambient => format!("ambient ({l})"),
                Some(&l) => format!("lighting {l}"),
                None => "lighting ?".into(),
            },
        }
    }

    fn step(&mut self, ctx: &mut Ctx, steps: f64) -> Vec<Cmd> {
        let spec = self.param_spec();
        let Some(v) = ctx.tracker.params.get(spec.key) else {
            return Vec::new();
        };
        let nv = match spec.kind {
            Kind::Bool => {
                if steps > 0.0 {
                    1.0
                } else {
                    0.0
                }
            }
            _ => {
                let raw = v + steps * spec.step;
                // Keep on the step grid so repeated presses do not drift.
                let snapped = (raw / spec.step).round() * spec.step;
                snapped.clamp(spec.min, spec.max)
            }
        };
        if nv == v {
            let end = if steps > 0.0 { "largest" } else { "smallest" };
            ctx.info(format!(
                "{} is at its {end} value, {}",
                spec.key,
                fmt_value(v)
            ));
            return Vec::new();
        }
        let mut p = ctx.tracker.params.clone();
        match p.set(spec.key, nv) {
            Ok(()) => {
                ctx.info(format!("{} {} → {}", spec.key, fmt_value(v), fmt_value(nv)));
                ctx.set_params(p)
            }
            Err(e) => {
                ctx.error(e.to_string());
                Vec::new()
            }
        }
    }
}
