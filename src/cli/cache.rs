//! `framewright cache info|clear [--cache DIR]`, and the `--cache DIR` / `--no-cache` options
//! the simulating commands share.

use super::{CmdResult, Failure, print_stdout};
use framewright::cache::{self, Cache};
use std::path::PathBuf;

/// The default cache folder: `$FRAMEWRIGHT_CACHE`, else `$XDG_CACHE_HOME/framewright`, else
/// `$HOME/.cache/framewright` (None when none is set).
pub fn default_dir() -> Option<PathBuf> {
    let var = |k: &str| {
        std::env::var_os(k)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
    };
    var("FRAMEWRIGHT_CACHE")
        .or_else(|| var("XDG_CACHE_HOME").map(|d| d.join("framewright")))
        .or_else(|| var("HOME").map(|d| d.join(".cache/framewright")))
}

/// Where results are cached.
#[derive(clap::Args, Clone, Debug)]
pub struct CacheArgs {
    /// The cache folder (default: $FRAMEWRIGHT_CACHE, else $XDG_CACHE_HOME/framewright, else
    /// ~/.cache/framewright). Share it between processes or machines freely.
    #[arg(long, value_name = "DIR")]
    pub cache: Option<PathBuf>,
    /// Neither read nor write the cache.
    #[arg(long, conflicts_with = "cache")]
    pub no_cache: bool,
}

impl CacheArgs {
    /// The cache to use, or None for --no-cache (or when no folder can be named, said once).
    pub fn open(&self) -> Option<Cache> {
        if self.no_cache {
            return None;
        }
        let dir = self.cache.clone().or_else(default_dir);
        if dir.is_none() {
            eprintln!(
                "warning: no cache folder (set FRAMEWRIGHT_CACHE or HOME, or give --cache DIR); \
                 going on without a cache"
            );
        }
        dir.map(Cache::new)
    }

    fn dir(&self) -> Result<PathBuf, Failure> {
        self.cache.clone().or_else(default_dir).ok_or_else(|| {
            Failure::bad_input("no cache folder: give --cache DIR or set FRAMEWRIGHT_CACHE")
        })
    }
}

/// Says (once) that the cache could not be written.
pub fn warn_if_unwritable(cache: Option<&Cache>) {
    if let Some(w) = cache.and_then(Cache::take_warning) {
        eprintln!("warning: {w}");
    }
}

#[derive(clap::Subcommand)]
pub enum CacheCommand {
    /// Where the cache is and how many walls it holds.
    Info {
        #[arg(long, value_name = "DIR")]
        cache: Option<PathBuf>,
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
    /// Remove every cached result (only files framewright wrote).
    Clear {
        #[arg(long, value_name = "DIR")]
        cache: Option<PathBuf>,
    },
}

pub fn run(cmd: CacheCommand) -> CmdResult {
    match cmd {
        CacheCommand::Info { cache, json } => {
            let dir = CacheArgs {
                cache,
                no_cache: false,
            }
            .dir()?;
            let info = cache::info(&dir).map_err(|e| {
                Failure::bad_input(format!("{}: cannot read the cache: {e}", dir.display()))
            })?;
            if json {
                let text = serde_json::to_string_pretty(&info)
                    .map_err(|e| Failure::bad_input(e.to_string()))?;
                print_stdout(&format!("{text}\n"))
            } else {
                print_stdout(&format!(
                    "{}\n{} simulated walls ({} with the motion for reports), {} walls simulated \
                     for `why`, {} reasoned model parts for `plan`, {:.1} MB\n",
                    info.dir.display(),
                    info.walls,
                    info.traces,
                    info.why_walls,
                    info.plan_parts,
                    info.bytes as f64 / 1e6
                ))
            }
        }
        CacheCommand::Clear { cache } => {
            let dir = CacheArgs {
                cache,
                no_cache: false,
            }
            .dir()?;
            let removed = cache::clear(&dir).map_err(|e| {
                Failure::bad_input(format!("{}: cannot clear the cache: {e}", dir.display()))
            })?;
            print_stdout(&format!(
                "removed {removed} entries from {}\n",
                dir.display()
            ))
        }
    }
}

/// The summary of a `simulate --shard` run.
pub fn print_shard(run: &framewright::cache::ShardRun, json: bool) -> CmdResult {
    if json {
        let text =
            serde_json::to_string_pretty(run).map_err(|e| Failure::bad_input(e.to_string()))?;
        print_stdout(&format!("{text}\n"))
    } else {
        print_stdout(&format!(
            "shard {}: {} walls ({} simulated, {} from the cache), {} walls in other shards\n",
            run.shard,
            run.walls.len(),
            run.cache.computed,
            run.cache.cached,
            run.other_walls
        ))
    }
}
