//! Where a bench's figures go: lines of text on stdout, or with `--json` one JSON document on
//! stdout at the end (the text lines then go to stderr, so a script reading stdout gets JSON
//! alone and a person watching still sees progress).

use std::fmt::Display;

use serde::Serialize;
use serde_json::{Map, Value};

/// A bench's output being gathered.
pub struct BenchOutput {
    json: bool,
    doc: Map<String, Value>,
}

impl BenchOutput {
    /// Output for the bench named `bench` (the JSON document's `bench` field).
    pub fn new(json: bool, bench: &str) -> Self {
        let mut doc = Map::new();
        doc.insert("bench".into(), bench.into());
        doc.insert("program".into(), crate::render::provenance::software().into());
        Self { json, doc }
    }

    /// A line of text for people.
    pub fn say(&self, line: impl Display) {
        if self.json {
            eprintln!("{line}");
        } else {
            println!("{line}");
        }
    }

    /// Sets a field of the JSON document.
    pub fn set(&mut self, key: &str, value: impl Serialize) {
        self.doc.insert(key.into(), to_value(value));
    }

    /// Appends to a list field of the JSON document (made on first use).
    pub fn push(&mut self, key: &str, value: impl Serialize) {
        let entry = self.doc.entry(key).or_insert_with(|| Value::Array(Vec::new()));
        if let Value::Array(list) = entry {
            list.push(to_value(value));
        }
    }

    /// Prints the JSON document, with `--json`.
    pub fn finish(self) {
        if self.json {
            match serde_json::to_string_pretty(&Value::Object(self.doc)) {
                Ok(text) => println!("{text}"),
                Err(e) => eprintln!("error: cannot write the JSON document: {e}"),
            }
        }
    }
}

fn to_value(value: impl Serialize) -> Value {
    serde_json::to_value(value).unwrap_or_else(|e| Value::String(format!("unserialisable: {e}")))
}
