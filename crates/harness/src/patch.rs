//! JSON merge patch (RFC 7396): how a preset edits the case's scene template.

use serde_json::Value;

/// Applies `patch` to `target` in place (RFC 7396): objects merge key by key, `null`
/// removes a key, any other value replaces the target's value.
pub fn merge_patch(target: &mut Value, patch: &Value) {
    let Value::Object(entries) = patch else {
        *target = patch.clone();
        return;
    };
    if !target.is_object() {
        *target = Value::Object(serde_json::Map::new());
    }
    if let Value::Object(map) = target {
        for (key, value) in entries {
            if value.is_null() {
                map.remove(key);
            } else {
                merge_patch(map.entry(key.clone()).or_insert(Value::Null), value);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn rfc7396_examples() {
        let mut v = json!({"a": "b", "c": {"d": "e", "f": "g"}});
        merge_patch(&mut v, &json!({"a": "z", "c": {"f": null}}));
        assert_eq!(v, json!({"a": "z", "c": {"d": "e"}}));
        let mut v = json!({"a": [1]});
        merge_patch(&mut v, &json!({"a": {"b": 1}}));
        assert_eq!(v, json!({"a": {"b": 1}}));
        let mut v = json!({"a": 1});
        merge_patch(&mut v, &json!({}));
        assert_eq!(v, json!({"a": 1}));
    }

    #[test]
    fn nested_scheme_patch_keeps_siblings() {
        let mut v = json!({"scheme": {"isph": {"ppe": {"solver": "bicgstab", "tolerance": 1e-3}, "free_surface_threshold": 1.5}}});
        merge_patch(
            &mut v,
            &json!({"scheme": {"isph": {"ppe": {"solver": "cg"}, "pressure_gradient": "difference"}}}),
        );
        assert_eq!(v["scheme"]["isph"]["ppe"]["solver"], "cg");
        assert_eq!(v["scheme"]["isph"]["ppe"]["tolerance"], 1e-3);
        assert_eq!(v["scheme"]["isph"]["free_surface_threshold"], 1.5);
        assert_eq!(v["scheme"]["isph"]["pressure_gradient"], "difference");
    }
}
