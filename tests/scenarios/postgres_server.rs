//! A throwaway PostgreSQL server for the shared-history tests: a cluster of its own in a
//! temporary folder, on a free port of the loopback address, stopped and removed when dropped.
//! The server's programs come from Debian's `postgresql` package (or any on the PATH);
//! PostgreSQL refuses to run as root, so as root they run as the `postgres` user.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A running server and where it lives.
pub struct Server {
    folder: PathBuf,
    bin: PathBuf,
    pub port: u16,
}

/// The folder holding `initdb`: on the PATH, else Debian's newest under /usr/lib/postgresql.
fn bin_folder() -> PathBuf {
    let on_path = std::env::var_os("PATH").and_then(|path| {
        std::env::split_paths(&path).find(|folder| folder.join("initdb").is_file())
    });
    let debian = || {
        let mut versions: Vec<PathBuf> = std::fs::read_dir("/usr/lib/postgresql")
            .ok()?
            .filter_map(|e| Some(e.ok()?.path().join("bin")))
            .filter(|bin| bin.join("initdb").is_file())
            .collect();
        versions.sort();
        versions.pop()
    };
    on_path.or_else(debian).expect(
        "the PostgreSQL server's programs (initdb, pg_ctl): install Debian's `postgresql` \
         (scripts/setup-debian.sh does)",
    )
}

fn is_root() -> bool {
    let out = Command::new("id").arg("-u").output().unwrap();
    String::from_utf8_lossy(&out.stdout).trim() == "0"
}

/// `program` of the server with `args`, as the `postgres` user when this process is root.
fn command(bin: &Path, program: &str, args: &[&str]) -> Command {
    let path = bin.join(program);
    let mut command = match is_root() {
        true => {
            let mut c = Command::new("runuser");
            c.args(["-u", "postgres", "--"]).arg(path);
            c
        }
        false => Command::new(path),
    };
    command.args(args);
    command
}

/// Runs `program` with `args`, which must succeed.
fn checked(bin: &Path, program: &str, args: &[&str]) -> Output {
    let out = command(bin, program, args).output().unwrap();
    assert!(
        out.status.success(),
        "{program} {args:?}: {}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

fn free_port() -> u16 {
    let listener = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    listener.local_addr().unwrap().port()
}

impl Server {
    /// A new cluster for the test `name`, started.
    pub fn start(name: &str) -> Self {
        let bin = bin_folder();
        let folder = std::env::temp_dir().join(format!("pgd-pg-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&folder);
        std::fs::create_dir_all(&folder).unwrap();
        if is_root() {
            let owner = Command::new("chown").arg("postgres:").arg(&folder).status();
            assert!(owner.unwrap().success());
        }
        let data = folder.join("data");
        let data_arg = data.to_string_lossy().into_owned();
        checked(
            &bin,
            "initdb",
            &[
                "-D",
                &data_arg,
                "-U",
                "postgres",
                "-A",
                "trust",
                "-E",
                "UTF8",
                "--no-sync",
            ],
        );
        let server = Self {
            folder,
            bin,
            port: free_port(),
        };
        server.run();
        server
    }

    /// Starts the server (again, after [`Self::stop`]).
    pub fn run(&self) {
        let options = format!(
            "-p {} -c listen_addresses=127.0.0.1 -c unix_socket_directories={} -c fsync=off",
            self.port,
            self.folder.display()
        );
        let (data, log) = (self.folder.join("data"), self.folder.join("log"));
        checked(
            &self.bin,
            "pg_ctl",
            &[
                "-D",
                &data.to_string_lossy(),
                "-l",
                &log.to_string_lossy(),
                "-o",
                &options,
                "-w",
                "start",
            ],
        );
    }

    /// Stops the server, at once.
    pub fn stop(&self) {
        let data = self.folder.join("data");
        checked(
            &self.bin,
            "pg_ctl",
            &[
                "-D",
                &data.to_string_lossy(),
                "-m",
                "immediate",
                "-w",
                "stop",
            ],
        );
    }

    /// The URL of database `name` as `user`, creating the database (owned by `postgres`).
    pub fn database(&self, name: &str) -> String {
        self.sql("postgres", &format!("CREATE DATABASE {name}"));
        self.url("postgres", name)
    }

    /// The URL of database `name` as `user`.
    pub fn url(&self, user: &str, name: &str) -> String {
        format!("postgres://{user}@127.0.0.1:{}/{name}", self.port)
    }

    /// Runs `sql` on database `name` as the superuser.
    pub fn sql(&self, name: &str, sql: &str) {
        let mut client =
            postgres::Client::connect(&self.url("postgres", name), postgres::NoTls).unwrap();
        client.batch_execute(sql).unwrap();
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        let data = self.folder.join("data");
        let stop = ["-D", &data.to_string_lossy(), "-m", "immediate", "stop"].map(str::to_owned);
        let stop: Vec<&str> = stop.iter().map(String::as_str).collect();
        let _ = command(&self.bin, "pg_ctl", &stop).output();
        let _ = std::fs::remove_dir_all(&self.folder);
    }
}
