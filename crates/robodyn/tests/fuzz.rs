//! A mutation fuzzer for the model loaders (stable Rust: a seeded generator, no cargo-fuzz). It
//! mutates the URDF, MJCF and TOML files of `models/` and `testdata/` — byte flips, truncation,
//! swapped tags and attributes, huge, negative and non-finite numbers, deep nesting, joints made
//! into cycles — and feeds them to the loaders. Every case must end in `Ok` or `Err`: never a
//! panic, a hang or unbounded memory. A model that loads is also run through RNEA and ABA at its
//! neutral configuration, which must return too.
//!
//! The mesh readers get the same treatment on mutated STL and OBJ files of `testdata/meshes/`,
//! through every inertia mode.
//!
//! `cargo test --test fuzz` runs `DEFAULT_CASES` cases from a fixed seed (a few seconds);
//! `scripts/fuzz --minutes 60` runs it longer with fresh seeds (`ROBODYN_FUZZ_SECONDS`,
//! `ROBODYN_FUZZ_SEED`).

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use robodyn::io::{load_dh_str, load_mjcf_str, load_urdf_str, LoadOptions};
use robodyn::{algo, Data, Model};
use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// Cases the test command runs.
const DEFAULT_CASES: usize = 20_000;
/// One case may take at most this long (a hang is a failure).
const CASE_TIME_LIMIT: Duration = Duration::from_secs(10);
/// Numbers the mutations write in place of a file's numbers.
const ODD_NUMBERS: [&str; 12] = [
    "1e308", "-1e308", "1e-320", "-0", "nan", "inf", "-inf", "-1", "0", "1e30", "-3.5e12", "0x10",
];

#[derive(Clone, Copy, Debug)]
enum Format {
    Urdf,
    Mjcf,
    Toml,
}

fn repository() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Every model file of the repository the loaders read, with its format.
fn corpus() -> Vec<(PathBuf, Format, String)> {
    let mut files = Vec::new();
    let mut folders = vec![repository().join("models"), repository().join("testdata")];
    while let Some(folder) = folders.pop() {
        for entry in std::fs::read_dir(&folder).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                folders.push(path);
                continue;
            }
            let format = match path.extension().and_then(|e| e.to_str()) {
                Some("urdf") => Format::Urdf,
                Some("xml") => Format::Mjcf,
                Some("toml") => Format::Toml,
                _ => continue,
            };
            let text = std::fs::read_to_string(&path).unwrap();
            files.push((path, format, text));
        }
    }
    files.sort_by(|a, b| a.0.cmp(&b.0));
    files
}

/// A random byte range of `text` on character boundaries.
fn span(rng: &mut StdRng, text: &str) -> (usize, usize) {
    let boundary = |mut k: usize| {
        while !text.is_char_boundary(k) {
            k -= 1;
        }
        k
    };
    let a = boundary(rng.random_range(0..=text.len()));
    let b = boundary(rng.random_range(a..=text.len().min(a + 64)));
    (a, b)
}

/// The positions of every match of `pattern` in `text`.
fn positions(text: &str, pattern: &str) -> Vec<usize> {
    text.match_indices(pattern).map(|(k, _)| k).collect()
}

/// One mutation of `text`.
fn mutate(rng: &mut StdRng, text: &str) -> String {
    let mut out = text.to_string();
    match rng.random_range(0..9) {
        // flip a few bytes (invalid UTF-8 becomes U+FFFD, as a reader of text sees it)
        0 => {
            let mut bytes = out.into_bytes();
            for _ in 0..rng.random_range(1..8) {
                if bytes.is_empty() {
                    break;
                }
                let k = rng.random_range(0..bytes.len());
                bytes[k] ^= 1 << rng.random_range(0..8);
            }
            out = String::from_utf8_lossy(&bytes).into_owned();
        }
        // truncate
        1 => {
            let (a, _) = span(rng, text);
            out.truncate(a);
        }
        // delete a span
        2 => {
            let (a, b) = span(rng, text);
            out.replace_range(a..b, "");
        }
        // duplicate a span somewhere else
        3 => {
            let (a, b) = span(rng, text);
            let piece = text[a..b].to_string();
            let (c, _) = span(rng, text);
            out.insert_str(c, &piece);
        }
        // a number becomes an odd one
        4 => {
            let numbers: Vec<(usize, usize)> = text
                .char_indices()
                .filter(|(_, c)| c.is_ascii_digit())
                .map(|(k, _)| (k, k + 1))
                .collect();
            if let Some(&(k, end)) = numbers.get(rng.random_range(0..numbers.len().max(1))) {
                let odd = ODD_NUMBERS[rng.random_range(0..ODD_NUMBERS.len())];
                out.replace_range(k..end, odd);
            }
        }
        // swap two element names or two attribute names
        5 => {
            let words: Vec<&str> = text
                .split(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                .filter(|w| w.len() > 1)
                .collect();
            if words.len() > 2 {
                let first = words[rng.random_range(0..words.len())];
                let second = words[rng.random_range(0..words.len())];
                out = text
                    .replacen(first, "\u{0}", 1)
                    .replacen(second, first, 1)
                    .replacen('\u{0}', second, 1);
            }
        }
        // deep nesting: wrap a span of elements in many copies of an element
        6 => {
            let tags = positions(text, "<body");
            let tag = if tags.is_empty() { "link" } else { "body" };
            let depth = rng.random_range(100..5000);
            let (a, _) = span(rng, text);
            let opening = format!("<{tag} name=\"n\">").repeat(depth);
            let closing = format!("</{tag}>").repeat(depth);
            out.insert_str(a, &(opening + &closing));
        }
        // a cycle: a joint's parent and child exchanged, or a body's name reused
        7 => {
            out = text
                .replacen("<parent link=", "<x link=", 1)
                .replacen("<child link=", "<parent link=", 1)
                .replacen("<x link=", "<child link=", 1);
            if let Some(k) = positions(&out, "name=\"").get(1).copied() {
                out.insert_str(k + 6, "base");
            }
        }
        // a random line repeated many times
        _ => {
            let lines: Vec<&str> = text.lines().collect();
            if !lines.is_empty() {
                let line = lines[rng.random_range(0..lines.len())];
                let (a, _) = span(rng, text);
                out.insert_str(a, &format!("{line}\n").repeat(rng.random_range(2..200)));
            }
        }
    }
    out
}

/// Loads `text` as `format` and, if it loads, runs RNEA and ABA at the neutral configuration.
fn exercise(format: Format, text: &str) {
    let model: Option<Model> = match format {
        Format::Urdf => load_urdf_str(text, "fuzz.urdf", LoadOptions::default()).ok(),
        Format::Mjcf => load_mjcf_str(text, "fuzz.xml").ok(),
        Format::Toml => load_dh_str(text, "fuzz.toml").ok(),
    };
    if let Some(model) = model {
        let mut data = Data::new(&model);
        let q = model.neutral();
        let zeros = vec![0.0; model.nv];
        let tau = algo::rnea(&model, &mut data, q.as_slice(), &zeros, &zeros, None)
            .map(|tau| tau.as_slice().to_vec());
        if let Ok(tau) = tau {
            let _ = algo::aba(&model, &mut data, q.as_slice(), &zeros, &tau, None);
        }
    }
}

/// Runs one case on its own thread: a panic or a hang fails with the case to reproduce it.
fn run_case(format: Format, text: String, label: &str) {
    let (sender, receiver) = mpsc::channel();
    let input = text.clone();
    let worker = std::thread::Builder::new()
        .stack_size(8 << 20)
        .spawn(move || {
            let outcome = std::panic::catch_unwind(|| exercise(format, &input));
            let _ = sender.send(outcome.is_ok());
        })
        .unwrap();
    match receiver.recv_timeout(CASE_TIME_LIMIT) {
        Ok(true) => {
            worker.join().unwrap();
        }
        Ok(false) => {
            let saved = std::env::temp_dir().join("robodyn-fuzz-panic.txt");
            std::fs::write(&saved, &text).unwrap();
            panic!(
                "{label}: the loader panicked; the input is in {}",
                saved.display()
            );
        }
        Err(_) => {
            let saved = std::env::temp_dir().join("robodyn-fuzz-hang.txt");
            std::fs::write(&saved, &text).unwrap();
            panic!(
                "{label}: no answer within {CASE_TIME_LIMIT:?}; the input is in {}",
                saved.display()
            );
        }
    }
}

#[test]
fn mutated_model_files_end_in_ok_or_err() {
    let files = corpus();
    assert!(
        files.len() >= 8,
        "the corpus holds only {} files",
        files.len()
    );
    let seed: u64 = std::env::var("ROBODYN_FUZZ_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(2026);
    let deadline = std::env::var("ROBODYN_FUZZ_SECONDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .map(|seconds| Instant::now() + Duration::from_secs(seconds));
    let mut rng = StdRng::seed_from_u64(seed);
    let mut cases = 0;
    loop {
        let done = match deadline {
            Some(deadline) => Instant::now() >= deadline,
            None => cases >= DEFAULT_CASES,
        };
        if done {
            break;
        }
        let (path, format, text) = &files[rng.random_range(0..files.len())];
        // up to three mutations on top of each other
        let mut mutated = text.clone();
        for _ in 0..rng.random_range(1..=3) {
            mutated = mutate(&mut rng, &mutated);
        }
        run_case(
            *format,
            mutated,
            &format!("seed {seed}, case {cases}, {}", path.display()),
        );
        cases += 1;
    }
    println!("fuzz: {cases} cases from seed {seed}, no panic, no hang");
}

#[test]
fn a_chain_nested_to_the_limit_loads_and_one_deeper_is_refused() {
    let chain = |depth: usize| {
        let mut text = String::from("<mujoco><worldbody>");
        for k in 0..depth {
            text += &format!("<body name=\"b{k}\" pos=\"0 0 0.1\"><joint/><geom size=\"0.01\"/>");
        }
        text + &"</body>".repeat(depth) + "</worldbody></mujoco>"
    };
    // the loaders recurse once per level: 8 MiB of stack (a thread's default on Linux) is enough
    // at the limit, even unoptimised
    let worker = std::thread::Builder::new()
        .stack_size(8 << 20)
        .spawn(move || {
            // <mujoco>, <worldbody> and the last <geom> are three more levels
            let deepest = robodyn::io::MAX_NESTING - 3;
            let model = load_mjcf_str(&chain(deepest), "chain.xml").unwrap();
            assert_eq!(model.nv, deepest);
            let error = load_mjcf_str(&chain(deepest + 1), "chain.xml").unwrap_err();
            assert!(error.to_string().contains("nested more than"), "{error}");
        })
        .unwrap();
    worker.join().unwrap();
}

#[test]
fn mutated_mesh_files_end_in_ok_or_err() {
    use robodyn::io::mesh::{read_mesh, MeshInertia};
    let folder = repository().join("testdata/meshes");
    let mut meshes: Vec<(String, Vec<u8>)> = std::fs::read_dir(&folder)
        .unwrap()
        .map(|entry| entry.unwrap().path())
        .filter_map(|path| {
            let extension = path.extension()?.to_str()?.to_string();
            matches!(extension.as_str(), "stl" | "obj")
                .then(|| (extension, std::fs::read(&path).unwrap()))
        })
        .collect();
    meshes.sort();
    assert!(meshes.len() >= 4);
    let mut rng = StdRng::seed_from_u64(7);
    for case in 0..DEFAULT_CASES / 4 {
        let (extension, bytes) = &meshes[rng.random_range(0..meshes.len())];
        let mut mutated = bytes.clone();
        for _ in 0..rng.random_range(1..6) {
            match rng.random_range(0..3) {
                0 if !mutated.is_empty() => {
                    let k = rng.random_range(0..mutated.len());
                    mutated[k] ^= 1 << rng.random_range(0..8);
                }
                1 => mutated.truncate(rng.random_range(0..=mutated.len())),
                _ => {
                    let k = rng.random_range(0..=mutated.len());
                    mutated.insert(k, rng.random());
                }
            }
        }
        let extension = extension.clone();
        let outcome = std::panic::catch_unwind(move || {
            if let Ok(file) = read_mesh(&mutated, &extension) {
                let mesh = file.mesh;
                if mesh.check().is_ok() {
                    for mode in [
                        MeshInertia::Legacy,
                        MeshInertia::Exact,
                        MeshInertia::Shell,
                        MeshInertia::Convex,
                    ] {
                        let _ = mesh.mass_properties(mode);
                    }
                }
            }
        });
        assert!(
            outcome.is_ok(),
            "case {case}: reading a mutated mesh panicked"
        );
    }
}
