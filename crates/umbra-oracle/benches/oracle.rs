fn main() {} // placeholder (lead): the oracle engineer replaces this
