//! How a model is loaded and its removals tested: the flags shared by `plan`, `collect`,
//! `bench`, `check` and `robot check`, built from the settings table (group `Model`). Every
//! flag is optional; a flag left out takes the request's default.

use super::settings::{ModelGroup, SettingArgs};
use super::Map;
use clap::Args;

/// Loading and the removal test.
#[derive(Args, Debug, Clone, Default)]
pub struct ModelArgs {
    /// The settings of loading and the removal test.
    #[command(flatten)]
    pub settings: SettingArgs<ModelGroup>,
    /// Old spelling of `--overlaps lenient`.
    #[arg(long, hide = true, conflicts_with = "overlaps")]
    pub ignore_overlapping: bool,
}

impl ModelArgs {
    /// The request keys these flags set.
    pub fn put(&self, map: &mut Map) {
        self.settings.put(map);
        if self.ignore_overlapping {
            map.insert("overlaps".into(), "lenient".into());
        }
    }
}
