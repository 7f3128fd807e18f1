// Prints "<class> <LCM_FINGERPRINT as unsigned hex>" for each class named on the command line, loading
// it from the class path (the lcm-spy types jar), as lcm-spy does.
public class FingerprintDump {
  public static void main(String[] args) throws Exception {
    for (String name : args) {
      long fp = Class.forName(name).getField("LCM_FINGERPRINT").getLong(null);
      System.out.println(name + " " + Long.toHexString(fp));
    }
  }
}
