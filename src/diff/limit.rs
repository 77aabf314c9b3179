//! `--fail-above METRIC=VALUE`: limits on the metrics of a [`DiffReport`], for CI.

use std::str::FromStr;

use serde::Serialize;
use thiserror::Error;

use super::DiffReport;

/// A metric that can be limited. All grow with the difference; PSNR is left out because
/// a limit on RMSE says the same (`psnr = -20 log10 rmse`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum LimitMetric {
    Rmse,
    Mae,
    /// The largest absolute sample error.
    Max,
    /// The share (0 to 1) of pixels above the threshold.
    Above,
    /// The coverage (silhouette) mismatch, in pixels.
    Coverage,
    FlipMean,
    FlipMedian,
    FlipMax,
}

impl LimitMetric {
    pub const ALL: [LimitMetric; 8] = [
        LimitMetric::Rmse,
        LimitMetric::Mae,
        LimitMetric::Max,
        LimitMetric::Above,
        LimitMetric::Coverage,
        LimitMetric::FlipMean,
        LimitMetric::FlipMedian,
        LimitMetric::FlipMax,
    ];

    pub fn name(self) -> &'static str {
        match self {
            LimitMetric::Rmse => "rmse",
            LimitMetric::Mae => "mae",
            LimitMetric::Max => "max",
            LimitMetric::Above => "above",
            LimitMetric::Coverage => "coverage",
            LimitMetric::FlipMean => "flip-mean",
            LimitMetric::FlipMedian => "flip-median",
            LimitMetric::FlipMax => "flip-max",
        }
    }

    /// The metric's value in `report`; `None` for coverage when an image has no alpha.
    pub fn value(self, report: &DiffReport) -> Option<f64> {
        Some(match self {
            LimitMetric::Rmse => report.rmse,
            LimitMetric::Mae => report.mae,
            LimitMetric::Max => report.max_abs,
            LimitMetric::Above => report.above_share,
            LimitMetric::Coverage => report.coverage_mismatch? as f64,
            LimitMetric::FlipMean => report.flip.mean,
            LimitMetric::FlipMedian => report.flip.weighted_median,
            LimitMetric::FlipMax => report.flip.max,
        })
    }
}

/// `METRIC=VALUE`: the check fails when the metric is greater than `max`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Limit {
    pub metric: LimitMetric,
    pub max: f64,
}

#[derive(Debug, Error, PartialEq)]
pub enum LimitParseError {
    #[error("expected METRIC=VALUE, e.g. rmse=0.01")]
    NoEquals,
    #[error("unknown metric '{0}'; expected one of {names}", names = metric_names())]
    UnknownMetric(String),
    #[error("'{0}' is not a finite non-negative number")]
    BadValue(String),
}

fn metric_names() -> String {
    let names: Vec<&str> = LimitMetric::ALL.iter().map(|m| m.name()).collect();
    names.join(", ")
}

impl FromStr for Limit {
    type Err = LimitParseError;

    fn from_str(s: &str) -> Result<Limit, LimitParseError> {
        let (name, value) = s.split_once('=').ok_or(LimitParseError::NoEquals)?;
        let name = name.trim();
        let metric = LimitMetric::ALL
            .into_iter()
            .find(|m| m.name() == name)
            .ok_or_else(|| LimitParseError::UnknownMetric(name.to_string()))?;
        let value = value.trim();
        let max = value
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite() && *v >= 0.0)
            .ok_or_else(|| LimitParseError::BadValue(value.to_string()))?;
        Ok(Limit { metric, max })
    }
}

/// A limit that was exceeded, with the value that exceeded it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Exceeded {
    pub metric: LimitMetric,
    pub value: f64,
    pub max: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_every_metric_and_refuses_malformed_limits() {
        for m in LimitMetric::ALL {
            let limit: Limit = format!("{}=0.25", m.name()).parse().unwrap();
            assert_eq!(
                limit,
                Limit {
                    metric: m,
                    max: 0.25
                }
            );
        }
        assert_eq!("rmse".parse::<Limit>(), Err(LimitParseError::NoEquals));
        assert!(matches!(
            "psnr=30".parse::<Limit>(),
            Err(LimitParseError::UnknownMetric(_))
        ));
        for bad in ["rmse=x", "rmse=-1", "rmse=inf", "rmse=NaN", "rmse="] {
            assert!(
                matches!(bad.parse::<Limit>(), Err(LimitParseError::BadValue(_))),
                "{bad}"
            );
        }
    }
}
