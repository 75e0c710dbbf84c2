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
    pub key: String,
    pub role: Role,
}

impl ApiKey {
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

#[cfg(test)]
mod tests {
    use super::*;

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
