//! `--executor local|slurm` and the Slurm options, shared by `validate` and `bench`
//! (README "Sweeps on a cluster").

use anyhow::bail;
use meniscus_harness::slurm::{Cluster, SlurmOptions};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Duration;

/// Where the runs that are not cached run.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum Executor {
    /// On this machine, `--jobs` at a time.
    #[default]
    Local,
    /// On a Slurm cluster, as `sbatch --array` jobs (from a login node).
    Slurm,
}

/// The executor flags.
#[derive(Debug, clap::Args)]
pub struct ExecutorArgs {
    /// Where runs that are not cached run: `local` (this machine) or `slurm` (job arrays
    /// through sbatch; the options below).
    #[arg(long, value_enum, default_value_t = Executor::Local)]
    executor: Executor,
    /// Slurm partition [default: the cluster's default partition].
    #[arg(long, value_name = "NAME")]
    partition: Option<String>,
    /// Slurm account to charge.
    #[arg(long, value_name = "NAME")]
    account: Option<String>,
    /// Time limit of each task, in sbatch's --time format (minutes, hh:mm:ss, days-hh:mm).
    #[arg(long, value_name = "TIME")]
    time_limit: Option<String>,
    /// CPUs (threads) of each task.
    #[arg(long, value_name = "N", default_value_t = 1)]
    cpus_per_task: usize,
    /// Most tasks of an array running at once (per array: a sweep of more runs than the
    /// cluster's MaxArraySize takes several) [default: as many as Slurm allows].
    #[arg(long, value_name = "N")]
    max_tasks: Option<usize>,
    /// Spool directory, on a file system the compute nodes share [default:
    /// <workspace>/target/slurm-spool].
    #[arg(long, value_name = "DIR")]
    spool: Option<PathBuf>,
    /// The meniscus binary the tasks run, reachable from the nodes [default: the one beside
    /// this xtask binary, built by `cargo build -p meniscus-cli`].
    #[arg(long, value_name = "FILE")]
    meniscus: Option<PathBuf>,
}

impl ExecutorArgs {
    /// The Slurm cluster to run on, checked before anything is submitted (`None`: local).
    /// A Slurm option without `--executor slurm` is an error.
    pub fn connect(&self, workspace: &Path) -> anyhow::Result<Option<Arc<Cluster>>> {
        if self.executor == Executor::Local {
            let given = [
                ("--partition", self.partition.is_some()),
                ("--account", self.account.is_some()),
                ("--time-limit", self.time_limit.is_some()),
                ("--cpus-per-task", self.cpus_per_task != 1),
                ("--max-tasks", self.max_tasks.is_some()),
                ("--spool", self.spool.is_some()),
                ("--meniscus", self.meniscus.is_some()),
            ];
            if let Some((flag, _)) = given.iter().find(|(_, set)| *set) {
                bail!("{flag} applies to `--executor slurm` only");
            }
            return Ok(None);
        }
        let meniscus = match &self.meniscus {
            Some(path) => path.clone(),
            None => std::env::current_exe()?
                .parent()
                .map(|dir| dir.join(format!("meniscus{}", std::env::consts::EXE_SUFFIX)))
                .unwrap_or_default(),
        };
        let opts = SlurmOptions {
            partition: self.partition.clone(),
            account: self.account.clone(),
            time_limit: self.time_limit.clone(),
            cpus_per_task: self.cpus_per_task,
            max_tasks: self.max_tasks,
            spool: self.spool.clone().unwrap_or_else(|| workspace.join("target").join("slurm-spool")),
            meniscus: std::path::absolute(&meniscus).unwrap_or(meniscus),
            poll: Duration::from_secs(2),
        };
        Ok(Some(Arc::new(Cluster::connect(opts)?)))
    }
}
