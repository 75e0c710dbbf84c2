//! API keys and their roles. `ROBOCAL_API_KEYS` lists keys separated by
//! commas, each optionally followed by `:role` (`k1:admin,k2:read,k3:operate`);
//! a key without a role is `admin`. The roles nest: `admin` ⊇ `operate` ⊇
//! `read`. Which role each route needs is decided in `crate::http::auth`.

use std::fmt;

/// What a key may do. Ordered: a role grants everything a lower one grants.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Role {
    /// Reads (GET): robots, sets, calibrations, versions, reports, the console.
    Read,
    /// `read` plus computations on the active model and check poses: solve,
    /// program filter, measurement plans, checks.
    Operate,
    /// Everything: robots, uploads, calibrations, versions, tools and frames.
    Admin,
}

impl Role {
    /// Every role, lowest first.
    pub const ALL: [Role; 3] = [Role::Read, Role::Operate, Role::Admin];

    /// The name written after `key:`.
    pub fn name(self) -> &'static str {
        match self {
            Role::Read => "read",
            Role::Operate => "operate",
            Role::Admin => "admin",
        }
    }

    /// What the role allows, for `serve --help`.
    pub fn allows(self) -> &'static str {
        match self {
            Role::Read => "GET requests (robots, sets, jobs, versions, reports, the console)",
            Role::Operate => {
                "what `read` can, plus solve, program filter, measurement plans and checks"
            }
            Role::Admin => "everything (robots, uploads, calibrations, versions, tools, frames)",
        }
    }

    /// True when a key of this role may do what `needed` is required for.
    pub fn grants(self, needed: Role) -> bool {
        self >= needed
    }

    /// The names of all roles, `read, operate, admin`.
    pub fn names() -> String {
        Role::ALL.map(Role::name).join(", ")
    }
}

impl fmt::Display for Role {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Role {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Role::ALL
            .into_iter()
            .find(|r| r.name() == s)
            .ok_or_else(|| format!("unknown role `{s}`; the roles are {}", Role::names()))
    }
}

/// One accepted key and its role. `Debug` does not print the key.
#[derive(Clone, PartialEq, Eq)]
pub struct ApiKey {
    /// The key as the client sends it after `Bearer `.
    pub key: String,
    /// What the key may do.
    pub role: Role,
}

impl ApiKey {
    /// The key `key` with role `role`.
    pub fn new(key: impl Into<String>, role: Role) -> Self {
        ApiKey {
            key: key.into(),
            role,
        }
    }
}

impl fmt::Debug for ApiKey {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "ApiKey(*** : {})", self.role)
    }
}

/// Parses a `ROBOCAL_API_KEYS` value: entries separated by commas, blanks
/// ignored, `key` or `key:role` (the role after the last `:`). An unknown
/// role, an empty key or a key listed twice is an error naming the entry's
/// position (never the key).
pub fn parse_keys(text: &str) -> Result<Vec<ApiKey>, String> {
    let mut keys: Vec<ApiKey> = Vec::new();
    let entries = text.split(',').map(str::trim).filter(|e| !e.is_empty());
    for (i, entry) in entries.enumerate() {
        let n = i + 1;
        let (key, role) = match entry.rsplit_once(':') {
            Some((key, role)) => {
                let role = role
                    .trim()
                    .parse()
                    .map_err(|e| format!("entry {n}: {e} (written `key:role`)"))?;
                (key.trim(), role)
            }
            None => (entry, Role::Admin),
        };
        if key.is_empty() {
            return Err(format!("entry {n}: the key before `:` is empty"));
        }
        if keys.iter().any(|k| k.key == key) {
            return Err(format!("entry {n}: the same key is listed twice"));
        }
        keys.push(ApiKey::new(key, role));
    }
    Ok(keys)
}

/// How a service is exposed, decided at start from where it listens, its
/// keys and the operator's explicit choice.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Exposure {
    /// Keys are set: every route but the health checks needs one.
    Keyed,
    /// No keys, listening on loopback only: open to this host's processes.
    OpenLoopback,
    /// No keys on a non-loopback address, by the operator's explicit choice
    /// (`--allow-open-writes`): open to the network, warned at every start.
    OpenNetwork,
}

/// The variable and flag that let a service without keys serve a network.
pub const ALLOW_OPEN_WRITES: &str = "ROBOCAL_ALLOW_OPEN_WRITES";

/// Decides whether a service may start: without keys it serves writes on a
/// non-loopback address only by the operator's explicit choice, since anyone
/// on a cell's network could then replace a robot's model or a tool's TCP and
/// move the robot somewhere else. The error names the fixes.
pub fn exposure(
    loopback: bool,
    keys: &[ApiKey],
    allow_open_writes: bool,
) -> Result<Exposure, String> {
    match (keys.is_empty(), loopback, allow_open_writes) {
        (false, _, _) => Ok(Exposure::Keyed),
        (true, true, _) => Ok(Exposure::OpenLoopback),
        (true, false, true) => Ok(Exposure::OpenNetwork),
        (true, false, false) => Err(format!(
            "refusing to serve a non-loopback address without API keys: anyone on the network could replace \
             a robot's model, a version or a tool. Set ROBOCAL_API_KEYS (e.g. ROBOCAL_API_KEYS=$(robocal keygen)) \
             or ROBOCAL_API_KEYS_FILE (a file of keys, e.g. a container secret); or bind 127.0.0.1; or, to serve \
             the network with every route open on purpose, pass --allow-open-writes ({ALLOW_OPEN_WRITES}=1)"
        )),
    }
}

/// A new random key for `ROBOCAL_API_KEYS`: 256 bits from the operating
/// system's generator, base64url without padding (43 characters).
pub fn new_key() -> String {
    use base64::Engine;
    use rand::RngCore;
    let mut bytes = [0u8; 32];
    rand::rngs::OsRng.fill_bytes(&mut bytes);
    base64::engine::general_purpose::URL_SAFE_NO_PAD.encode(bytes)
}

/// Keys shorter than this are accepted but warned about at start: they can
/// be guessed.
pub const SHORT_KEY: usize = 16;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn without_keys_only_loopback_or_an_explicit_choice_serves() {
        let keys = parse_keys("k1:admin").unwrap();
        assert_eq!(exposure(false, &keys, false), Ok(Exposure::Keyed));
        assert_eq!(exposure(true, &keys, false), Ok(Exposure::Keyed));
        assert_eq!(exposure(true, &[], false), Ok(Exposure::OpenLoopback));
        assert_eq!(exposure(false, &[], true), Ok(Exposure::OpenNetwork));
        let e = exposure(false, &[], false).unwrap_err();
        for fix in [
            "ROBOCAL_API_KEYS",
            "ROBOCAL_API_KEYS_FILE",
            "robocal keygen",
            "127.0.0.1",
            "--allow-open-writes",
            ALLOW_OPEN_WRITES,
        ] {
            assert!(e.contains(fix), "{fix} in {e}");
        }
    }

    #[test]
    fn new_keys_are_long_distinct_and_parse() {
        let a = new_key();
        let b = new_key();
        assert_eq!(a.len(), 43);
        assert_ne!(a, b);
        assert!(a
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_'));
        let keys = parse_keys(&format!("{a}:operate")).unwrap();
        assert_eq!(
            (keys[0].key.as_str(), keys[0].role),
            (a.as_str(), Role::Operate)
        );
    }

    #[test]
    fn keys_take_a_role_and_default_to_admin() {
        let keys = parse_keys(" k1:admin, k2:read ,k3:operate,k4,, a:b:read ").unwrap();
        let got: Vec<(&str, Role)> = keys.iter().map(|k| (k.key.as_str(), k.role)).collect();
        assert_eq!(
            got,
            [
                ("k1", Role::Admin),
                ("k2", Role::Read),
                ("k3", Role::Operate),
                ("k4", Role::Admin),
                ("a:b", Role::Read),
            ]
        );
        assert!(parse_keys("").unwrap().is_empty());
    }

    #[test]
    fn bad_entries_are_refused_without_showing_the_key() {
        let e = parse_keys("s3cret:reader").unwrap_err();
        assert!(e.contains("unknown role `reader`"), "{e}");
        assert!(e.contains("read, operate, admin"), "{e}");
        assert!(!e.contains("s3cret"), "{e}");
        assert!(parse_keys("ok,:read").unwrap_err().contains("entry 2"));
        assert!(parse_keys("k:read,k:admin").unwrap_err().contains("twice"));
        assert!(parse_keys("k:").unwrap_err().contains("unknown role ``"));
    }

    #[test]
    fn roles_nest() {
        for (i, a) in Role::ALL.into_iter().enumerate() {
            for (j, b) in Role::ALL.into_iter().enumerate() {
                assert_eq!(a.grants(b), i >= j, "{a} grants {b}");
            }
        }
    }
}
